//! A compiled MuJoCo model to the [`Tree`], SPEC (21.1): the arrays of an
//! `mjModel` as plain data (a front reads them; MuJoCo's compiler read the
//! MJCF, never this crate), so an MJCF arm goes through the same reduction
//! as a URDF one.
//!
//! Bodies are links (body 0, the world, is the root); a body without joints
//! hangs from its parent by a fixed joint named `weld:BODY`; a body with
//! joints j1 … jk hangs by them in order, through links named `BODY:jI`
//! between them. A joint's frame sits at its anchor (`jnt_pos`) with the
//! body's axes, so a link's frame is its body's moved by the last joint's
//! anchor: the body's inertial, its sites and its child bodies are expressed
//! from there. A hinge is revolute (continuous when not limited), a slide
//! prismatic, a ball a ball, a free joint floating; `offset` is `qpos0`.
//! Sites are named frames, the sites of force sensors tool frames. The
//! joints of a fixed tendon of two or more joints are coupled. A joint equality (`mjEQ_JOINT`, active)
//! y − y0 = a0 + a1 (x − x0) + … makes y a mimic of x (multiplier a1, offset
//! y0 + a0 − a1 x0); with no x, y is locked at y0 + a0 (a fixed joint).
//! The effort of a joint is the sum over the actuators that drive it
//! through a joint transmission of |gear| × the actuator's force bound
//! (`forcerange` if force-limited; a motor's (fixed gain, no bias)
//! |gain| × `ctrlrange` if control-limited; otherwise none, and the sum is
//! NaN), bounded by the joint's `actfrcrange` when `actfrclimited`.

use super::error::{DescriptionError, ErrorKind};
use super::tree::{
    motion, JointType, Link, LinkInertial, Mimic, NamedFrame, Origin, Tree, TreeJoint,
};
use crate::cartesian::chain::Transform;
use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;
use nalgebra::Vector3;

/// MuJoCo's `mjtJoint`: free.
pub const MJ_JOINT_FREE: i32 = 0;
/// MuJoCo's `mjtJoint`: ball.
pub const MJ_JOINT_BALL: i32 = 1;
/// MuJoCo's `mjtJoint`: slide.
pub const MJ_JOINT_SLIDE: i32 = 2;
/// MuJoCo's `mjtJoint`: hinge.
pub const MJ_JOINT_HINGE: i32 = 3;
/// MuJoCo's `mjtEq`: a joint equality.
pub const MJ_EQ_JOINT: i32 = 2;

/// The arrays of a compiled MuJoCo model the tree needs (names as MuJoCo
/// gives them; "" for unnamed). Indices are MuJoCo's ids.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MujocoArrays {
    /// The model's name.
    pub model_name: String,
    /// Per body (0 is the world): its name.
    pub body_name: Vec<String>,
    /// Its parent body.
    pub body_parentid: Vec<usize>,
    /// Its frame in its parent's (m), at `qpos0`.
    pub body_pos: Vec<[f64; 3]>,
    /// Its orientation in its parent's, [w, x, y, z].
    pub body_quat: Vec<[f64; 4]>,
    /// Its mass (kg).
    pub body_mass: Vec<f64>,
    /// Its centre of mass in its frame (m).
    pub body_ipos: Vec<[f64; 3]>,
    /// The principal axes of its inertia in its frame, [w, x, y, z].
    pub body_iquat: Vec<[f64; 4]>,
    /// Its principal inertia about the centre of mass (kg m²).
    pub body_inertia: Vec<[f64; 3]>,
    /// The share of its weight gravity compensation lifts (`gravcomp`);
    /// empty: none on any body.
    pub body_gravcomp: Vec<f64>,
    /// Per joint: its name.
    pub jnt_name: Vec<String>,
    /// Its `mjtJoint` type.
    pub jnt_type: Vec<i32>,
    /// Its body.
    pub jnt_bodyid: Vec<usize>,
    /// Its anchor in its body's frame (m).
    pub jnt_pos: Vec<[f64; 3]>,
    /// Its axis in its body's frame.
    pub jnt_axis: Vec<[f64; 3]>,
    /// Whether its range applies.
    pub jnt_limited: Vec<bool>,
    /// Its range (rad or m).
    pub jnt_range: Vec<[f64; 2]>,
    /// Its value at `qpos0` (its first qpos).
    pub jnt_qpos0: Vec<f64>,
    /// Its armature (kg m²; its first dof's).
    pub jnt_armature: Vec<f64>,
    /// Its damping (N m s/rad; its first dof's).
    pub jnt_damping: Vec<f64>,
    /// Its friction loss (N m; its first dof's).
    pub jnt_frictionloss: Vec<f64>,
    /// Whether its actuator force is limited.
    pub jnt_actfrclimited: Vec<bool>,
    /// Its actuator force range (N m).
    pub jnt_actfrcrange: Vec<[f64; 2]>,
    /// Per site: its name.
    pub site_name: Vec<String>,
    /// Its body.
    pub site_bodyid: Vec<usize>,
    /// Its position in its body's frame (m).
    pub site_pos: Vec<[f64; 3]>,
    /// Its orientation in its body's frame, [w, x, y, z].
    pub site_quat: Vec<[f64; 4]>,
    /// Per actuator: its `mjtTrn` transmission (0 joint, 1 joint in parent).
    pub actuator_trntype: Vec<i32>,
    /// Its target (a joint id for a joint transmission).
    pub actuator_trnid: Vec<i64>,
    /// Its first gear.
    pub actuator_gear: Vec<f64>,
    /// Whether its force is limited.
    pub actuator_forcelimited: Vec<bool>,
    /// Its force range.
    pub actuator_forcerange: Vec<[f64; 2]>,
    /// Whether its control is limited.
    pub actuator_ctrllimited: Vec<bool>,
    /// Its control range.
    pub actuator_ctrlrange: Vec<[f64; 2]>,
    /// Its `mjtGain` (0 fixed).
    pub actuator_gaintype: Vec<i32>,
    /// Its first gain parameter.
    pub actuator_gain: Vec<f64>,
    /// Its `mjtBias` (0 none).
    pub actuator_biastype: Vec<i32>,
    /// Per equality: its `mjtEq` type.
    pub eq_type: Vec<i32>,
    /// Its first object (a joint id for a joint equality).
    pub eq_obj1id: Vec<i64>,
    /// Its second object (−1: none).
    pub eq_obj2id: Vec<i64>,
    /// Its first five data (a joint equality's polynomial coefficients).
    pub eq_data: Vec<[f64; 5]>,
    /// Whether it is active at the start.
    pub eq_active: Vec<bool>,
    /// The sites a force sensor measures at (tool frames).
    pub force_sites: Vec<usize>,
    /// Per fixed tendon: its name and the joints it couples.
    pub tendons: Vec<(String, Vec<usize>)>,
}

fn bad(source: &str, message: String) -> DescriptionError {
    DescriptionError::new(ErrorKind::Structure, format!("{source}: {message}"))
}

fn named(name: &str, kind: &str, i: usize) -> String {
    if name.is_empty() {
        format!("{kind}#{i}")
    } else {
        name.into()
    }
}

fn shifted(p: [f64; 3], by: [f64; 3]) -> [f64; 3] {
    [p[0] - by[0], p[1] - by[1], p[2] - by[2]]
}

impl MujocoArrays {
    /// Per kind of object (body, jnt, site, actuator, eq): its prefix, its
    /// count (the length of its names or types) and the lengths of its
    /// arrays, padded with the count (a table: one row per kind).
    fn length_groups(&self) -> [(&'static str, usize, [usize; 8]); 5] {
        [
            (
                "body",
                self.body_name.len(),
                [
                    self.body_parentid.len(),
                    self.body_pos.len(),
                    self.body_quat.len(),
                    self.body_mass.len(),
                    self.body_ipos.len(),
                    self.body_iquat.len(),
                    self.body_inertia.len(),
                    self.body_name.len(),
                ],
            ),
            (
                "jnt",
                self.jnt_name.len(),
                [
                    self.jnt_type.len(),
                    self.jnt_bodyid.len(),
                    self.jnt_pos.len(),
                    self.jnt_axis.len(),
                    self.jnt_limited.len(),
                    self.jnt_range.len(),
                    self.jnt_qpos0.len(),
                    self.jnt_armature.len(),
                ],
            ),
            (
                "site",
                self.site_name.len(),
                [
                    self.site_bodyid.len(),
                    self.site_pos.len(),
                    self.site_quat.len(),
                    self.site_name.len(),
                    self.site_name.len(),
                    self.site_name.len(),
                    self.site_name.len(),
                    self.site_name.len(),
                ],
            ),
            (
                "actuator",
                self.actuator_trntype.len(),
                [
                    self.actuator_trnid.len(),
                    self.actuator_gear.len(),
                    self.actuator_forcelimited.len(),
                    self.actuator_forcerange.len(),
                    self.actuator_ctrllimited.len(),
                    self.actuator_ctrlrange.len(),
                    self.actuator_gaintype.len(),
                    self.actuator_gain.len(),
                ],
            ),
            (
                "eq",
                self.eq_type.len(),
                [
                    self.eq_obj1id.len(),
                    self.eq_obj2id.len(),
                    self.eq_data.len(),
                    self.eq_active.len(),
                    self.eq_type.len(),
                    self.eq_type.len(),
                    self.eq_type.len(),
                    self.eq_type.len(),
                ],
            ),
        ]
    }

    /// Every array of one kind has the same length, and every id names an
    /// object that exists (a front's mistake otherwise, named): the
    /// [`length_groups`](Self::length_groups), the joints' drive arrays and
    /// the actuators' bias types, a world at least, each body's parent
    /// before it, the force sites and the bodies of joints and sites.
    fn check_lengths(&self, source: &str) -> Result<(), DescriptionError> {
        for (what, n, lens) in self.length_groups() {
            if lens.iter().any(|&l| l != n) {
                return Err(bad(
                    source,
                    format!("the {what}_* arrays differ in length: give one entry per {what}"),
                ));
            }
        }
        let extra = [
            self.jnt_damping.len(),
            self.jnt_frictionloss.len(),
            self.jnt_actfrclimited.len(),
            self.jnt_actfrcrange.len(),
        ];
        if extra.iter().any(|&l| l != self.jnt_name.len())
            || self.actuator_biastype.len() != self.actuator_trntype.len()
        {
            return Err(bad(
                source,
                "the jnt_* or actuator_* arrays differ in length: give one entry per joint and \
                 per actuator"
                    .into(),
            ));
        }
        if self.body_name.is_empty() {
            return Err(bad(source, "it has no bodies (not even the world)".into()));
        }
        for (b, &p) in self.body_parentid.iter().enumerate().skip(1) {
            if p >= b {
                return Err(bad(
                    source,
                    format!("body {b} has the parent {p}, not a body before it"),
                ));
            }
        }
        if let Some(i) = self
            .force_sites
            .iter()
            .position(|&s| s >= self.site_name.len())
        {
            return Err(bad(source, format!("force_sites[{i}] is not a site")));
        }
        for (what, ids) in [
            ("jnt_bodyid", &self.jnt_bodyid),
            ("site_bodyid", &self.site_bodyid),
        ] {
            if let Some(i) = ids.iter().position(|&b| b >= self.body_name.len()) {
                return Err(bad(source, format!("{what}[{i}] is not a body")));
            }
        }
        Ok(())
    }

    /// The effort (N m or N) of joint `j`, NaN where none is stated.
    fn effort(&self, j: usize) -> f64 {
        let (mut total, mut any, mut unbounded) = (0.0, false, false);
        for a in 0..self.actuator_trntype.len() {
            let on_joint = matches!(self.actuator_trntype[a], 0 | 1)
                && usize::try_from(self.actuator_trnid[a]).ok() == Some(j);
            if !on_joint {
                continue;
            }
            any = true;
            let gear = self.actuator_gear[a].abs();
            let range = |r: [f64; 2]| r[0].abs().max(r[1].abs());
            if self.actuator_forcelimited[a] {
                total += gear * range(self.actuator_forcerange[a]);
            } else if self.actuator_gaintype[a] == 0
                && self.actuator_biastype[a] == 0
                && self.actuator_ctrllimited[a]
            {
                total += gear * self.actuator_gain[a].abs() * range(self.actuator_ctrlrange[a]);
            } else {
                unbounded = true;
            }
        }
        let mut effort = if any && !unbounded && total > 0.0 {
            total
        } else {
            f64::NAN
        };
        if self.jnt_actfrclimited[j] {
            let r = self.jnt_actfrcrange[j];
            let limit = r[0].abs().max(r[1].abs());
            if limit > 0.0 {
                effort = if effort.is_nan() {
                    limit
                } else {
                    effort.min(limit)
                };
            }
        }
        effort
    }

    /// The tree of the model, labelled `source` in messages (e.g.
    /// `"MJCF 'robot.xml'"`). Errors: arrays of one kind that differ in
    /// length, a body whose parent does not come before it, an object on a
    /// body that does not exist, and those of [`Tree::new`].
    pub fn tree(&self, source: &str) -> Result<Tree, DescriptionError> {
        self.check_lengths(source)?;
        let mut build = TreeBuild::new(self, source);
        for b in 0..self.body_name.len() {
            build.body(b)?;
        }
        let frames = build.frames();
        Tree::new(source, &self.model_name, build.links, build.joints, frames)
            .map(|t| t.in_dialect(super::tree::Dialect::Mujoco))
    }
}

/// One model's tree being built, body by body (SPEC (21.1), MJCF): the
/// names, each body's joints and what couples joints, read once from the
/// arrays; the links and joints so far.
struct TreeBuild<'m> {
    m: &'m MujocoArrays,
    source: &'m str,
    body_names: Vec<String>,
    joint_names: Vec<String>,
    /// Per body: its joints, in order.
    body_joints: Vec<Vec<usize>>,
    /// Per joint: the joint a joint equality makes it follow.
    mimic: Vec<Option<Mimic>>,
    /// Per joint: a0 of a joint equality without a second joint (locked at qpos0 + a0).
    locked: Vec<Option<f64>>,
    /// Per joint: the fixed tendon of two or more joints that couples it.
    coupled: Vec<Option<String>>,
    links: Vec<Link>,
    joints: Vec<TreeJoint>,
}

impl<'m> TreeBuild<'m> {
    /// The names (a world without one is "world"; an unnamed object
    /// `kind#i`), each body's joints and the couplings of the model `m`.
    fn new(m: &'m MujocoArrays, source: &'m str) -> Self {
        let nb = m.body_name.len();
        let body_names: Vec<String> = (0..nb)
            .map(|b| {
                if b == 0 && m.body_name[0].is_empty() {
                    "world".into()
                } else {
                    named(&m.body_name[b], "body", b)
                }
            })
            .collect();
        let joint_names: Vec<String> = (0..m.jnt_name.len())
            .map(|j| named(&m.jnt_name[j], "joint", j))
            .collect();
        let mut body_joints = alloc::vec![Vec::new(); nb];
        for (j, &b) in m.jnt_bodyid.iter().enumerate() {
            body_joints[b].push(j);
        }
        let (mimic, locked) = m.joint_equalities(&joint_names);
        Self {
            m,
            source,
            body_names,
            joint_names,
            body_joints,
            mimic,
            locked,
            coupled: m.coupled_joints(),
            links: Vec::with_capacity(nb),
            joints: Vec::new(),
        }
    }

    /// Body `b`'s link frame in its body frame: moved by its last joint's anchor.
    fn anchor(&self, b: usize) -> [f64; 3] {
        self.body_joints[b]
            .last()
            .map_or([0.0; 3], |&j: &usize| self.m.jnt_pos[j])
    }

    /// Body `b` as a link (its inertial from its link frame; none for the
    /// world) and, but for the world, the joints it hangs from its parent
    /// by: a weld, or its joints in order through links `BODY:jI`.
    fn body(&mut self, b: usize) -> Result<(), DescriptionError> {
        let m = self.m;
        let a = self.anchor(b);
        let mut link = Link::new(&self.body_names[b]);
        if b > 0 {
            let d = m.body_inertia[b];
            link.inertial = Some(LinkInertial {
                mass: m.body_mass[b],
                origin: Origin::PosQuat(shifted(m.body_ipos[b], a), m.body_iquat[b]),
                inertia: [[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]],
                gravcomp: m.body_gravcomp.get(b).copied().unwrap_or(0.0),
            });
        }
        self.links.push(link);
        if b == 0 {
            return Ok(());
        }
        let p = m.body_parentid[b];
        let parent = self.body_names[p].clone();
        // The body's frame in its parent's link frame.
        let body = Origin::PosQuat(shifted(m.body_pos[b], self.anchor(p)), m.body_quat[b]);
        let js = self.body_joints[b].clone();
        if js.is_empty() {
            self.joints.push(TreeJoint::new(
                &format!("weld:{}", self.body_names[b]),
                JointType::Fixed,
                &parent,
                &self.body_names[b],
                body,
            ));
            return Ok(());
        }
        let mut from = parent;
        let mut previous = [0.0; 3];
        for (k, &j) in js.iter().enumerate() {
            let child = if k + 1 == js.len() {
                self.body_names[b].clone()
            } else {
                let name = format!("{}:{}", self.body_names[b], self.joint_names[j]);
                self.links.push(Link::new(&name));
                name
            };
            let at = m.jnt_pos[j];
            let origin = if k == 0 {
                self.first_joint_origin(b, &body, at)?
            } else {
                Origin::XyzRpy(shifted(at, previous), [0.0; 3])
            };
            previous = at;
            let joint = self.joint(j, &from, &child, origin)?;
            self.joints.push(joint);
            from = child;
        }
        Ok(())
    }

    /// The origin of body `b`'s first joint, anchored `at` in the body
    /// whose frame in its parent's link frame is `body`.
    fn first_joint_origin(
        &self,
        b: usize,
        body: &Origin,
        at: [f64; 3],
    ) -> Result<Origin, DescriptionError> {
        let t = body.transform().map_err(|e| {
            bad(
                self.source,
                format!("body '{}' has a bad orientation: {e}", self.body_names[b]),
            )
        })?;
        let r = nalgebra::Matrix3::from_fn(|i, c| t.rotation[i][c]);
        let p = Vector3::from(t.translation) + r * Vector3::from(at);
        Ok(Origin::Matrix(Transform {
            translation: p.into(),
            rotation: t.rotation,
        }))
    }

    /// Joint `j` from link `from` to `child` at `origin`: its kind (a hinge
    /// continuous when not limited), and for a movable one its axis, offset,
    /// limits, effort, drive terms and couplings; locked by an equality, a
    /// fixed joint at qpos0 + a0.
    fn joint(
        &self,
        j: usize,
        from: &str,
        child: &str,
        origin: Origin,
    ) -> Result<TreeJoint, DescriptionError> {
        let m = self.m;
        let limited = m.jnt_limited[j];
        let kind = match m.jnt_type[j] {
            MJ_JOINT_HINGE if limited => JointType::Revolute,
            MJ_JOINT_HINGE => JointType::Continuous,
            MJ_JOINT_SLIDE => JointType::Prismatic,
            MJ_JOINT_BALL => JointType::Ball,
            MJ_JOINT_FREE => JointType::Floating,
            other => {
                return Err(bad(
                    self.source,
                    format!(
                        "joint '{}' has the unknown type {other}",
                        self.joint_names[j]
                    ),
                ))
            }
        };
        let mut joint = TreeJoint::new(&self.joint_names[j], kind, from, child, origin);
        if !kind.is_movable() {
            return Ok(joint);
        }
        joint.axis = m.jnt_axis[j];
        joint.offset = m.jnt_qpos0[j];
        if limited && m.jnt_range[j][0] < m.jnt_range[j][1] {
            joint.lower = m.jnt_range[j][0];
            joint.upper = m.jnt_range[j][1];
        } else if kind == JointType::Revolute {
            joint.kind = JointType::Continuous;
        }
        joint.effort = m.effort(j);
        joint.armature = m.jnt_armature[j];
        joint.damping = m.jnt_damping[j];
        joint.friction = m.jnt_frictionloss[j];
        joint.mimic = self.mimic[j].clone();
        joint.coupled = self.coupled[j].clone();
        if let Some(a0) = self.locked[j] {
            self.lock(&mut joint, j, kind, a0)?;
        }
        Ok(joint)
    }

    /// Joint `j` (of `kind`) locked by an equality: a fixed joint at qpos0 + a0.
    fn lock(
        &self,
        joint: &mut TreeJoint,
        j: usize,
        kind: JointType,
        a0: f64,
    ) -> Result<(), DescriptionError> {
        let fail = |e| bad(self.source, format!("joint '{}': {e}", self.joint_names[j]));
        let t = joint.origin.transform().map_err(fail)?;
        let f = t.check(j).map_err(fail)?;
        let axis = Vector3::from(joint.axis);
        let len = axis.norm();
        if len > 1e-12 {
            let m = f.then(&motion(kind == JointType::Prismatic, &(axis / len), a0));
            joint.origin = Origin::Matrix(Transform::from_parts(m.p, &m.r));
        }
        joint.kind = JointType::Fixed;
        joint.mimic = None;
        Ok(())
    }

    /// The sites as named frames on their bodies' links (a force sensor's
    /// site a tool frame).
    fn frames(&self) -> Vec<NamedFrame> {
        let m = self.m;
        (0..m.site_name.len())
            .map(|s| {
                let b = m.site_bodyid[s];
                NamedFrame {
                    name: named(&m.site_name[s], "site", s),
                    link: self.body_names[b].clone(),
                    origin: Origin::PosQuat(shifted(m.site_pos[s], self.anchor(b)), m.site_quat[s]),
                    tool: m.force_sites.contains(&s),
                }
            })
            .collect()
    }
}

impl MujocoArrays {
    /// The active joint equalities, per joint: y − y0 = a0 + a1 (x − x0)
    /// makes y a mimic of x (multiplier a1, offset y0 + a0 − a1 x0); with
    /// no x, y is locked at a0 from y0.
    fn joint_equalities(&self, joint_names: &[String]) -> (Vec<Option<Mimic>>, Vec<Option<f64>>) {
        let mut mimic: Vec<Option<Mimic>> = alloc::vec![None; self.jnt_name.len()];
        let mut locked: Vec<Option<f64>> = alloc::vec![None; self.jnt_name.len()];
        for e in 0..self.eq_type.len() {
            if self.eq_type[e] != MJ_EQ_JOINT || !self.eq_active[e] {
                continue;
            }
            let Some(y) = usize::try_from(self.eq_obj1id[e])
                .ok()
                .filter(|&y| y < joint_names.len())
            else {
                continue;
            };
            let d = self.eq_data[e];
            match usize::try_from(self.eq_obj2id[e])
                .ok()
                .filter(|&x| x < joint_names.len())
            {
                Some(x) => {
                    mimic[y] = Some(Mimic {
                        joint: joint_names[x].clone(),
                        multiplier: d[1],
                        offset: self.jnt_qpos0[y] + d[0] - d[1] * self.jnt_qpos0[x],
                    })
                }
                None => locked[y] = Some(d[0]),
            }
        }
        (mimic, locked)
    }

    /// Per joint: the fixed tendon of two or more joints that couples it,
    /// if one does (the last one).
    fn coupled_joints(&self) -> Vec<Option<String>> {
        let mut coupled: Vec<Option<String>> = alloc::vec![None; self.jnt_name.len()];
        for (t, (name, js)) in self.tendons.iter().enumerate() {
            if js.len() >= 2 {
                for &j in js {
                    if let Some(c) = coupled.get_mut(j) {
                        *c = Some(named(name, "tendon", t));
                    }
                }
            }
        }
        coupled
    }
}
