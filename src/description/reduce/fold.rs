//! The arm's bodies and drive from the tree: every held joint folded into
//! the link before it at the value it is held at, the inertials checked.

use super::*;

/// The value joint `j` is held at: its offset, or for a mimic joint the
/// multiplier times its master's offset plus its own.
pub(super) fn held_value(tree: &Tree, j: usize) -> f64 {
    let joint = &tree.joints()[j];
    match &joint.mimic {
        Some(m) => {
            let master = tree
                .joint_index(&m.joint)
                .map_or(0.0, |k| tree.joints()[k].offset);
            m.multiplier * master + m.offset
        }
        None => joint.offset,
    }
}

pub(super) fn config(tree: &Tree, e: Error) -> DescriptionError {
    DescriptionError::new(ErrorKind::Value, format!("{}: {e}", tree.source()))
}

/// The frame of joint `j`'s child link in its parent link's frame, with the
/// joint at `value` (fixed joints: their origin).
pub(super) fn joint_frame(tree: &Tree, j: usize, value: f64) -> Result<Frame, DescriptionError> {
    let joint = &tree.joints()[j];
    let origin = joint
        .origin
        .transform()
        .and_then(|t| t.check(j))
        .map_err(|e| config(tree, e))?;
    let shift = value - joint.offset;
    if !joint.kind.is_movable() || shift == 0.0 {
        return Ok(origin);
    }
    let axis = Vector3::from(joint.axis);
    let len = axis.norm();
    if len.partial_cmp(&1e-12) != Some(core::cmp::Ordering::Greater) {
        return Err(arm_error(
            tree,
            format!(
                "joint '{}' has a zero axis: give its <axis xyz>",
                joint.name
            ),
        ));
    }
    Ok(origin.then(&motion(
        joint.kind == JointType::Prismatic,
        &(axis / len),
        shift,
    )))
}

/// The arm's joints on the tree, for folding what is not the arm's into
/// what is (the chain and bodies of [`build`]).
pub(super) struct Fold<'t> {
    pub(super) tree: &'t Tree,
    /// Per joint: whether it is an arm joint.
    pub(super) on_arm: Vec<bool>,
    /// The first link folded into a body whose inertia no rigid body has.
    pub(super) unphysical: core::cell::RefCell<Option<DescriptionError>>,
}

impl Fold<'_> {
    /// The value joint `j` is folded at: an arm joint's offset, a held
    /// joint's held value.
    pub(super) fn value(&self, j: usize) -> f64 {
        if self.on_arm[j] {
            self.tree.joints()[j].offset
        } else {
            held_value(self.tree, j)
        }
    }

    /// The chain to `tip_link` (SPEC §16): fixed and held joints fold into
    /// the next arm joint's origin; what is left after the last one, and
    /// the frame `tip_frame`, is the tip's origin.
    pub(super) fn chain(
        &self,
        tip_link: usize,
        tip_frame: Option<usize>,
    ) -> Result<(Vec<Joint>, Transform), DescriptionError> {
        let tree = self.tree;
        let joints = tree.joints();
        let mut chain = Vec::new();
        let mut pending = Frame::IDENTITY;
        for j in tree.path_to(tip_link) {
            if self.on_arm[j] {
                let origin = pending.then(&joint_frame(tree, j, joints[j].offset)?);
                let joint = &joints[j];
                chain.push(Joint {
                    kind: if joint.kind == JointType::Prismatic {
                        JointKind::Prismatic
                    } else {
                        JointKind::Revolute
                    },
                    origin: Transform::from_parts(origin.p, &origin.r),
                    axis: joint.axis,
                    offset: joint.offset,
                });
                pending = Frame::IDENTITY;
            } else {
                pending = pending.then(&joint_frame(tree, j, self.value(j))?);
            }
        }
        if let Some(f) = tip_frame {
            let t = tree.frames()[f]
                .origin
                .transform()
                .and_then(|t| t.check(0))
                .map_err(|e| config(tree, e))?;
            pending = pending.then(&t);
        }
        Ok((chain, Transform::from_parts(pending.p, &pending.r)))
    }

    /// The links arm joint `a` moves as one body (its child link and every
    /// link below it that no arm joint moves): the links [`Fold::body`] sums.
    pub(super) fn links(&self, a: usize) -> Vec<usize> {
        let tree = self.tree;
        let mut out = Vec::new();
        let mut todo = VecDeque::from([tree.joint_links(a).1]);
        while let Some(l) = todo.pop_front() {
            out.push(l);
            for &j in tree.child_joints(l) {
                if !self.on_arm[j] {
                    todo.push_back(tree.joint_links(j).1);
                }
            }
        }
        out
    }

    /// The body arm joint `a` moves (SPEC (20.1)): its child link and every
    /// link it carries through joints that are not the arm's, as one
    /// inertial in the joint's frame; and what gravity compensation lifts
    /// of it.
    pub(super) fn body(&self, a: usize) -> Result<(Inertial, Lifted), DescriptionError> {
        let tree = self.tree;
        let start = tree.joint_links(a).1;
        let (mut m, mut h, mut io) = (0.0, Vector3::zeros(), Matrix3::zeros());
        let (mut lm, mut lh) = (0.0, Vector3::zeros());
        let mut todo = VecDeque::from([(start, Frame::IDENTITY)]);
        while let Some((l, at)) = todo.pop_front() {
            if let Some(inertial) = tree.links()[l].inertial.filter(|i| i.has_mass()) {
                if let Err(e) = physical(tree, l, &inertial.inertia) {
                    self.unphysical.borrow_mut().get_or_insert(e);
                }
                let f = inertial
                    .origin
                    .transform()
                    .and_then(|t| t.check(l))
                    .map_err(|e| config(tree, e))?;
                let f = at.then(&f);
                let ic = Matrix3::from_fn(|i, k| inertial.inertia[i][k]);
                let c = f.p;
                let mass = inertial.mass;
                m += mass;
                h += mass * c;
                lm += inertial.gravcomp * mass;
                lh += inertial.gravcomp * mass * c;
                io += f.r * ic * f.r.transpose()
                    + mass * (Matrix3::identity() * c.norm_squared() - c * c.transpose());
            }
            for &j in tree.child_joints(l) {
                if !self.on_arm[j] {
                    let next = at.then(&joint_frame(tree, j, self.value(j))?);
                    todo.push_back((tree.joint_links(j).1, next));
                }
            }
        }
        let com = if m > 0.0 { h / m } else { Vector3::zeros() };
        let ic = io - m * (Matrix3::identity() * com.norm_squared() - com * com.transpose());
        let ic = (ic + ic.transpose()) * 0.5;
        let body = Inertial {
            mass: m,
            origin: Transform {
                translation: com.into(),
                ..Transform::IDENTITY
            },
            inertia: core::array::from_fn(|i| core::array::from_fn(|k| ic[(i, k)])),
        };
        let lifted = Lifted {
            mass: lm,
            moment: lh.into(),
        };
        Ok((body, lifted))
    }
}

/// Link `l`'s inertia `i` is one a rigid body has (positive semi-definite),
/// else an error naming the link and the file: a link the arm moves with a
/// negative principal moment makes the mass matrix indefinite.
pub(super) fn physical(tree: &Tree, l: usize, i: &[[f64; 3]; 3]) -> Result<(), DescriptionError> {
    let Err(m) = physical_inertia(i) else {
        return Ok(());
    };
    let v = |x: f64| {
        if x != 0.0 && x.abs() < 1e-4 {
            format!("{x:e}")
        } else {
            format!("{x}")
        }
    };
    let rows = i.map(|r| format!("[{}, {}, {}]", v(r[0]), v(r[1]), v(r[2])));
    Err(DescriptionError::new(
        ErrorKind::Value,
        format!(
            "{}: link '{}' has the inertia [{}] kg m², which no rigid body has: its \
             principal moments are {:.3e}, {:.3e}, {:.3e} kg m², one negative (the arm's \
             mass matrix would not be positive; MuJoCo refuses it too): correct the link's \
             <inertia> (ixx, iyy, izz ≥ 0 and |ixy| ≤ √(ixx iyy), …)",
            tree.source(),
            tree.links()[l].name,
            rows.join(", "),
            m[0],
            m[1],
            m[2]
        ),
    ))
}

/// Joint `j` of the tree as an arm joint: its limits (±∞ when continuous),
/// effort, velocity and drive terms.
pub(super) fn arm_joint(tree: &Tree, j: usize) -> ArmJoint {
    let joint = &tree.joints()[j];
    let unlimited = joint.kind == JointType::Continuous;
    ArmJoint {
        name: joint.name.clone(),
        index: j,
        prismatic: joint.kind == JointType::Prismatic,
        lower: if unlimited {
            f64::NEG_INFINITY
        } else {
            joint.lower
        },
        upper: if unlimited {
            f64::INFINITY
        } else {
            joint.upper
        },
        effort: joint.effort,
        velocity: joint.velocity,
        armature: joint.armature,
        damping: joint.damping,
        friction: joint.friction,
    }
}

/// The [`Arm`] of the reduction `r` (the end of SPEC (21.2)): the arm
/// joints `arm` from `base` to the tip, their chain and bodies, and every
/// held joint with its value and reason.
/// SPEC (21.5): a description whose dynamics has nothing to move — no link
/// the arm moves states a mass, or the last arm joint moves less than 1e-9
/// kg m² about its axis (1e-9 kg along it), its armature (rotor inertia)
/// included — named with the file, the joint and what to do.
fn unmovable(
    tree: &Tree,
    arm: &[usize],
    chain: &[Joint],
    inertials: &[Inertial],
) -> Option<DescriptionError> {
    const FLOOR: f64 = 1e-9;
    if inertials.iter().all(|i| i.mass == 0.0) {
        return Some(DescriptionError::new(
            ErrorKind::Value,
            format!(
                "{}: no link the arm moves states a mass (<inertial>): the file describes \
                 the arm's kinematics alone, and its dynamics (the plant, the rule's gains, \
                 computed torque) needs each link's mass and inertia: use a description of \
                 the arm with its links' <inertial> (the maker's, or example-robot-data's)",
                tree.source()
            ),
        ));
    }
    let (&j, joint, body) = (arm.last()?, chain.last()?, inertials.last()?);
    let name = &tree.joints()[j].name;
    let a = Vector3::from(joint.axis).normalize();
    let armature = tree.joints()[j].armature;
    let (moved, unit, what) = if tree.joints()[j].kind == JointType::Prismatic {
        (body.mass + armature, "kg", "along")
    } else {
        let r = Matrix3::from_fn(|i, k| body.origin.rotation[i][k]);
        let ic = Matrix3::from_fn(|i, k| body.inertia[i][k]);
        let c = Vector3::from(body.origin.translation);
        let axial = a.dot(&(r * ic * r.transpose() * a));
        let along = a.dot(&c);
        (
            axial + body.mass * (c.norm_squared() - along * along) + armature,
            "kg m²",
            "about",
        )
    };
    // A NaN is refused too.
    (moved.is_nan() || moved < FLOOR).then(|| {
        DescriptionError::new(
            ErrorKind::Value,
            format!(
                "{}: the last arm joint '{name}' moves {moved:e} {unit} {what} its axis \
                 (less than {FLOOR:e}, its armature included): its link states no inertia \
                 there, so no torque controls it: give the link its <inertial> or the joint \
                 an armature, or hold the joint (fix=['{name}'])",
                tree.source()
            ),
        )
    })
}

pub(super) fn build(
    r: &Reduction<'_>,
    base: usize,
    arm: Vec<usize>,
    tip_name: String,
    tip_link: Option<usize>,
    tip_frame: Option<usize>,
) -> Result<Arm, DescriptionError> {
    let tree = r.tree;
    let last_link = tree.joint_links(arm[arm.len() - 1]).1;
    let fold = Fold {
        tree,
        on_arm: on_arm(tree.joints().len(), &arm),
        unphysical: core::cell::RefCell::new(None),
    };
    let (chain, tip_origin) = fold.chain(tip_link.unwrap_or(last_link), tip_frame)?;
    let (inertials, lifted) = arm
        .iter()
        .map(|&a| fold.body(a))
        .collect::<Result<(Vec<_>, Vec<_>), _>>()?;
    if let Some(e) = unmovable(tree, &arm, &chain, &inertials) {
        fold.unphysical.borrow_mut().get_or_insert(e);
    }
    let held = r
        .held
        .iter()
        .map(|(&j, why)| HeldJoint {
            name: tree.joints()[j].name.clone(),
            index: j,
            value: held_value(tree, j),
            reason: why.clone(),
        })
        .collect();
    Ok(Arm {
        source: tree.source().into(),
        base: tree.links()[base].name.clone(),
        tip: tip_name,
        tip_is_frame: tip_frame.is_some(),
        joints: arm.iter().map(|&j| arm_joint(tree, j)).collect(),
        held,
        chain,
        tip_origin,
        balanced: {
            let moved: Vec<&str> = arm
                .iter()
                .flat_map(|&a| fold.links(a))
                .map(|l| tree.links()[l].name.as_str())
                .collect();
            tree.balanced()
                .iter()
                .filter(|b| moved.contains(&b.as_str()))
                .cloned()
                .collect()
        },
        inertials,
        lifted,
        inertia_error: fold.unphysical.into_inner(),
        warnings: r
            .held
            .iter()
            .filter(|(_, why)| matches!(why, Held::MimicOfNone { .. }))
            .map(|(_, why)| format!("{}: {why}", tree.source()))
            .collect(),
    })
}
