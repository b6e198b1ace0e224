//! The one reduction of a tree to the arm adaptimp drives, SPEC (21.2):
//! which chain, which joints are the arm's, the tip, what is held fixed and
//! why, and the arm's kinematics, bodies and drive terms.

use super::error::{DescriptionError, ErrorKind};
use super::tree::{motion, Dialect, JointType, Tree};
use crate::cartesian::chain::{Chain, Frame, Joint, JointKind, Transform};
use crate::cartesian::dynamics::{physical_inertia, Drive, Dynamics, Inertial, Lifted};
use crate::error::Error;
use alloc::collections::{BTreeMap, VecDeque};
use alloc::format;
use alloc::string::{String, ToString};
use alloc::vec::Vec;
use core::fmt;
use nalgebra::{Matrix3, Vector3};

/// Words that mark a joint as a gripper's when nothing in the structure
/// does (the last hint of (21.2), rule 5c), matched in any case.
pub const GRIPPER_WORDS: [&str; 5] = ["gripper", "finger", "jaw", "claw", "knuckle"];

/// Why a joint of the tree is not one of the arm's (SPEC (21.2)).
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Held {
    /// Named in `fix`.
    Asked,
    /// A mimic joint: it moves with its master.
    Mimic {
        /// The joint it follows.
        master: String,
    },
    /// A mimic joint whose master is not another joint of the description
    /// (off the arm; on the arm's way it is refused): held at its
    /// reference, the description's mistake said ([`Arm::warnings`]).
    MimicOfNone {
        /// What is wrong ([`Tree::mimic_error`]).
        why: String,
    },
    /// Coupled to other joints (a MuJoCo fixed tendon): it does not move
    /// on its own.
    Coupled {
        /// What couples it.
        by: String,
    },
    /// A joint of more than one coordinate (floating, planar, ball).
    Free {
        /// Its kind.
        kind: JointType,
    },
    /// A prismatic joint, when the arm is found without a `tip`.
    Prismatic,
    /// Below a hand: a link where two or more branches of joints start,
    /// each shorter than the arm that holds them.
    Hand {
        /// The hand's link.
        link: String,
    },
    /// The last joint of a chain that other joints mimic: a gripper's drive.
    GripperDrive {
        /// The joints that mimic it.
        followers: Vec<String>,
    },
    /// A last joint beside a tool frame, with no frame below it: a jaw.
    Jaw {
        /// The tool frame beside it.
        frame: String,
    },
    /// A joint whose name says it is a gripper's, after an arm joint whose
    /// name does not.
    Named {
        /// The word of [`GRIPPER_WORDS`] in its name.
        word: &'static str,
    },
    /// A drivable joint on another chain than the arm's.
    OffChain,
    /// A joint not on the way to the `tip` asked for.
    OffPath {
        /// The tip.
        tip: String,
    },
}

impl Held {
    /// Why the joint is held, in the words of `dialect` (a MuJoCo model's
    /// `free` and `slide` joints, a URDF's `floating` and `prismatic`).
    pub fn describe(&self, dialect: Dialect) -> String {
        match (dialect, self) {
            (Dialect::Mujoco, Self::Free { kind }) => format!(
                "a {} joint: an arm's joints have one coordinate each",
                kind.name_in(dialect)
            ),
            (Dialect::Mujoco, Self::Prismatic) => String::from(
                "a slide (a lift, a rail or a finger): the arm found without tip= is of hinges; \
                 a tip beyond it drives it",
            ),
            _ => self.to_string(),
        }
    }
}

impl fmt::Display for Held {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Asked => f.write_str("asked (fix=)"),
            Self::Mimic { master } => {
                write!(
                    f,
                    "mimics '{master}': it moves with '{master}', not on its own"
                )
            }
            Self::MimicOfNone { why } => write!(
                f,
                "{why}: held at its reference position (correct its <mimic joint=…>)"
            ),
            Self::Coupled { by } => write!(
                f,
                "coupled to other joints by '{by}': it does not move on its own"
            ),
            Self::Free { kind } => write!(
                f,
                "a {} joint: an arm's joints have one coordinate each",
                kind.urdf_name()
            ),
            Self::Prismatic => f.write_str(
                "prismatic (a lift, a rail or a finger): the arm found without tip= is revolute; \
                 a tip beyond it drives it",
            ),
            Self::Hand { link } => write!(
                f,
                "in the hand at '{link}' (branches of joints start there: two or more each \
                 shorter than the arm, or three or more none longer)"
            ),
            Self::GripperDrive { followers } => {
                f.write_str("drives a gripper (")?;
                for (i, name) in followers.iter().enumerate() {
                    let sep = if i == 0 { "" } else { ", " };
                    write!(f, "{sep}'{name}'")?;
                }
                f.write_str(" mimic it)")
            }
            Self::Jaw { frame } => write!(
                f,
                "moves a jaw beside the tool frame '{frame}' (the arm ends at the tool)"
            ),
            Self::Named { word } => write!(f, "a gripper's (its name contains '{word}')"),
            Self::OffChain => f.write_str("off the arm's chain (another arm, a leg, a head)"),
            Self::OffPath { tip } => write!(f, "not on the way to '{tip}'"),
        }
    }
}

/// A joint of the arm, base to tip.
#[derive(Clone, Debug, PartialEq)]
pub struct ArmJoint {
    /// Its name in the description.
    pub name: String,
    /// Its index in [`Tree::joints`].
    pub index: usize,
    /// Prismatic (m, N) rather than revolute (rad, N m).
    pub prismatic: bool,
    /// Position limits (rad or m); −∞ and +∞ for an unlimited joint.
    pub lower: f64,
    /// See `lower`.
    pub upper: f64,
    /// The drive's largest torque (N m) or force (N); NaN where the
    /// description states none.
    pub effort: f64,
    /// The largest speed (rad/s or m/s); NaN where none is stated.
    pub velocity: f64,
    /// Armature (kg m² or kg).
    pub armature: f64,
    /// Viscous damping (N m s/rad or N s/m).
    pub damping: f64,
    /// Dry friction loss (N m or N).
    pub friction: f64,
}

/// A joint of the tree that is not the arm's, held at `value`.
#[derive(Clone, Debug, PartialEq)]
pub struct HeldJoint {
    /// Its name.
    pub name: String,
    /// Its index in [`Tree::joints`].
    pub index: usize,
    /// The value (rad or m) it is held at: its `offset` (0 in a URDF,
    /// `qpos0` in MuJoCo), or a mimic's value when its master is at its own.
    pub value: f64,
    /// Why.
    pub reason: Held,
}

/// The arm of a tree (SPEC (21.2)): the result of [`reduce`].
#[derive(Clone, Debug, PartialEq)]
pub struct Arm {
    /// The description it came from (for messages).
    pub source: String,
    /// The root link (the world frame of the chain).
    pub base: String,
    /// The tip: a link, or a named frame if `tip_is_frame`.
    pub tip: String,
    /// Whether `tip` names a frame (a MuJoCo site) rather than a link.
    pub tip_is_frame: bool,
    /// The arm's joints, base to tip.
    pub joints: Vec<ArmJoint>,
    /// Every other joint with a coordinate (movable, floating, planar,
    /// ball), in the description's order, with the value it is held at and why.
    pub held: Vec<HeldJoint>,
    /// The chain (SPEC §16): the arm's joints only, each with the fixed
    /// and held joints before it folded into its origin.
    pub chain: Vec<Joint>,
    /// The last arm joint's frame → the tip.
    pub tip_origin: Transform,
    /// The links the arm moves whose inertia the reader balanced (SPEC
    /// (21.4)); the tree's others do not enter the arm's dynamics.
    pub balanced: Vec<String>,
    /// Per arm joint, the body it moves (SPEC (20.1)): its child link and
    /// every link carried by it through fixed and held joints, as one
    /// inertial in the joint's frame (mass, centre of mass, inertia about it).
    pub inertials: Vec<Inertial>,
    /// Per arm joint, what gravity compensation lifts of its body (MuJoCo's
    /// `gravcomp`: Σ gravcomp × mass and its first moment over its links, in
    /// the joint's frame, SPEC (20.1')); zeros without compensation.
    pub lifted: Vec<Lifted>,
    /// The first link the arm moves whose inertia no rigid body has (not
    /// positive semi-definite), named with the file: its dynamics
    /// ([`Arm::to_dynamics`]) is refused with it; its kinematics reads.
    pub inertia_error: Option<DescriptionError>,
    /// The description's mistakes the arm does not depend on, held and
    /// said (a front shows them: Python warns): a mimic joint off the arm
    /// whose master is not a joint of it ([`Held::MimicOfNone`]).
    pub warnings: Vec<String>,
}

impl Arm {
    /// The number of arm joints n.
    pub fn n(&self) -> usize {
        self.joints.len()
    }

    /// The arm's kinematics to its tip, as a [`Chain`] of `N` joints
    /// (`N` must be [`Arm::n`]; the chain's errors otherwise).
    pub fn to_chain<const N: usize>(&self) -> Result<Chain<N>, Error> {
        Chain::new(&self.chain, &self.tip_origin)
    }

    /// The arm's rigid-body dynamics under `gravity` (m/s², the base frame),
    /// as a [`Dynamics`] of `N` joints (the links alone; the description's
    /// drive terms are [`Arm::drive`], for [`Dynamics::with_drive`]).
    ///
    /// Errors: [`Arm::inertia_error`], and the dynamics' own (a mass or an
    /// inertia beyond 1e9, another N), named with the description.
    pub fn to_dynamics<const N: usize>(
        &self,
        gravity: [f64; 3],
    ) -> Result<Dynamics<N>, DescriptionError> {
        if let Some(e) = &self.inertia_error {
            return Err(e.clone());
        }
        let named =
            |e: Error| DescriptionError::new(ErrorKind::Value, format!("{}: {e}", self.source));
        let d = Dynamics::new(&self.chain, &self.inertials, gravity).map_err(named)?;
        if self.lifted.iter().all(|l| *l == Lifted::default()) {
            return Ok(d);
        }
        d.with_gravity_compensation(&self.chain, &self.lifted)
            .map_err(named)
    }

    /// The description's drive terms of the `N` arm joints (armature,
    /// damping, friction loss; SPEC (20.5)), or an error if `N` is not
    /// [`Arm::n`].
    pub fn drive<const N: usize>(&self) -> Result<Drive<N>, Error> {
        if self.joints.len() != N {
            return Err(Error::Condition {
                condition: "the arm has N joints (the Drive's N)",
                lhs: "arm joints",
                index: None,
                value: self.joints.len() as f64,
            });
        }
        let column = |f: fn(&ArmJoint) -> f64| {
            crate::types::Vector::<N>::from_iterator(self.joints.iter().map(f))
        };
        Ok(Drive {
            armature: column(|j| j.armature),
            damping: column(|j| j.damping),
            friction: column(|j| j.friction),
        })
    }

    /// The arm within `max` joints (the run-time API's
    /// [`MAX_JOINTS`](crate::dynamic::MAX_JOINTS)), else an error of kind
    /// [`ErrorKind::Arm`] naming its joints and what to do.
    pub fn within(&self, max: usize) -> Result<(), DescriptionError> {
        if self.n() <= max {
            return Ok(());
        }
        let names: Vec<&str> = self.joints.iter().map(|j| j.name.as_str()).collect();
        Err(DescriptionError::new(
            ErrorKind::Arm,
            format!(
                "{}: the arm has {} joints ({}); a chain has at most {max}: hold some with fix",
                self.source,
                self.n(),
                names.join(", ")
            ),
        ))
    }

    /// The reason joint `name` is held, if it is.
    pub fn held_reason(&self, name: &str) -> Option<&Held> {
        self.held.iter().find(|h| h.name == name).map(|h| &h.reason)
    }
}

fn arm_error(tree: &Tree, message: String) -> DescriptionError {
    DescriptionError::new(ErrorKind::Arm, format!("{}: {message}", tree.source()))
}

fn names_list<'a>(names: impl Iterator<Item = &'a str>) -> String {
    let mut out = String::from("[");
    for (i, n) in names.enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        out.push('\'');
        out.push_str(n);
        out.push('\'');
    }
    out.push(']');
    out
}

/// The word of [`GRIPPER_WORDS`] in `name`, if any.
fn gripper_word(name: &str) -> Option<&'static str> {
    let lower = name.to_lowercase();
    GRIPPER_WORDS.iter().copied().find(|w| lower.contains(w))
}

/// The working data of one reduction.
struct Reduction<'t> {
    tree: &'t Tree,
    held: BTreeMap<usize, Held>,
    /// Per joint: the joints that mimic it.
    followers: Vec<Vec<usize>>,
}

impl<'t> Reduction<'t> {
    fn drivable(&self, j: usize) -> bool {
        matches!(
            self.tree.joints()[j].kind,
            JointType::Revolute | JointType::Continuous
        ) && !self.held.contains_key(&j)
    }

    /// A link that is a frame: no mass, no joint below, carried by a fixed joint.
    fn is_frame_link(&self, l: usize) -> bool {
        let tree = self.tree;
        !tree.links()[l].inertial.is_some_and(|i| i.has_mass())
            && tree.child_joints(l).is_empty()
            && tree
                .parent_joint(l)
                .is_some_and(|j| tree.joints()[j].kind == JointType::Fixed)
    }

    /// The first tool frame on link `l` or on a link fixed to it (beside
    /// any movable joint of `l`): a named frame, or a frame link.
    fn frame_beside(&self, l: usize) -> Option<String> {
        let tree = self.tree;
        let mut todo = VecDeque::from([l]);
        while let Some(link) = todo.pop_front() {
            if let Some(&f) = tree.link_frames(link).first() {
                return Some(tree.frames()[f].name.clone());
            }
            if link != l && self.is_frame_link(link) {
                return Some(tree.links()[link].name.clone());
            }
            for &j in tree.child_joints(link) {
                if tree.joints()[j].kind == JointType::Fixed {
                    todo.push_back(tree.joint_links(j).1);
                }
            }
        }
        None
    }

    /// The links of the tree below `root`, parents before children.
    fn order(&self, root: usize) -> Vec<usize> {
        let mut order = Vec::new();
        let mut todo = VecDeque::from([root]);
        while let Some(l) = todo.pop_front() {
            order.push(l);
            for &j in self.tree.child_joints(l) {
                todo.push_back(self.tree.joint_links(j).1);
            }
        }
        order
    }
}

/// The arm of `tree` (SPEC (21.2)): the chain to `tip` (a link or a named
/// frame; None: found by the rule), with the joints named in `fix` held.
///
/// Errors (naming the description and what to do): `fix` names a joint the
/// tree does not have; `tip` is neither a link nor a frame; a floating,
/// planar or ball joint on the way to `tip`; several root links and no
/// `tip`; chains that tie for the arm (legs, two arms) and no `tip`; no
/// joint left to drive.
pub fn reduce(tree: &Tree, tip: Option<&str>, fix: &[&str]) -> Result<Arm, DescriptionError> {
    check_fix(tree, fix)?;
    let mut r = Reduction::new(tree);
    r.hold_always(fix);
    let tip = tip.or(r.tool_frame());
    let (tip_link, tip_frame) = resolve_tip(tree, tip)?;
    let (base, arm, tip_name) = match tip_link {
        Some(l) => {
            let tip_name = tip.unwrap_or_default();
            let arm = r.path_to_tip(l, tip_name, fix)?;
            (tree.root_of(l), arm, tip_name.to_string())
        }
        None => {
            let root = single_root(tree)?;
            if (0..tree.joints().len()).any(|j| tree.mimic_error(j).is_some()) {
                // A mimic of no joint is held; were the rule's arm to pass it
                // as a joint to drive, the arm would end short of it
                // silently: refused, as on the way to a tip given.
                let mut probe = Reduction::new(tree);
                probe.hold_always(fix);
                probe
                    .held
                    .retain(|_, why| !matches!(why, Held::MimicOfNone { .. }));
                if let Ok(arm) = find_chain(&mut probe, root) {
                    let end = tree.joint_links(arm[arm.len() - 1]).1;
                    on_the_way(tree, &tree.path_to(end), &tree.links()[end].name, fix)?;
                }
            }
            let arm = find_chain(&mut r, root)?;
            let last = arm[arm.len() - 1];
            let end = tree.joint_links(last).1;
            let tip_name = tree.links()[end].name.clone();
            // The joints the rule passes on its way are the arm's business
            // too (a floating one was held silently here, refused with the
            // same tip given).
            on_the_way(tree, &tree.path_to(end), &tip_name, fix)?;
            (root, arm, tip_name)
        }
    };
    build(&r, base, arm, tip_name, tip_link, tip_frame)
}

/// The joints on `path` (to `tip`) fit a chain: no floating, planar or ball
/// joint that `fix` does not name, no mimic joint of a joint the tree does
/// not have (its coordinate would be held silently: the arm one short).
fn on_the_way(
    tree: &Tree,
    path: &[usize],
    tip: &str,
    fix: &[&str],
) -> Result<(), DescriptionError> {
    let joints = tree.joints();
    for &j in path {
        let kind = joints[j].kind;
        let named = fix.contains(&joints[j].name.as_str());
        if matches!(
            kind,
            JointType::Floating | JointType::Planar | JointType::Ball
        ) && !named
        {
            return Err(arm_error(
                tree,
                format!(
                    "the joint '{}' on the way to '{tip}' is {}: a chain has {} joints only; \
                     give a tip below it or fix it with fix=",
                    joints[j].name,
                    kind.name_in(tree.dialect()),
                    match tree.dialect() {
                        Dialect::Urdf => "revolute, continuous, prismatic and fixed",
                        Dialect::Mujoco => "hinge and slide",
                    }
                ),
            ));
        }
        if let Some(why) = tree.mimic_error(j).filter(|_| !named) {
            return Err(arm_error(
                tree,
                format!(
                    "{why}, on the way to '{tip}': correct its <mimic joint=…>, or hold it \
                     with fix="
                ),
            ));
        }
    }
    Ok(())
}

/// Every joint `fix` names is the tree's; else an error listing the unknown
/// names and the movable joints there are.
fn check_fix(tree: &Tree, fix: &[&str]) -> Result<(), DescriptionError> {
    let unknown: Vec<&str> = fix
        .iter()
        .copied()
        .filter(|n| tree.joint_index(n).is_none())
        .collect();
    if unknown.is_empty() {
        return Ok(());
    }
    let movable = tree
        .joints()
        .iter()
        .filter(|j| j.kind.is_movable())
        .map(|j| j.name.as_str());
    Err(arm_error(
        tree,
        format!(
            "fix= names joints it does not have: {}; its movable joints are {}",
            names_list(unknown.into_iter()),
            names_list(movable)
        ),
    ))
}

/// The link and the frame `tip` names (rule 2 of (21.2)): a frame first (a
/// MuJoCo site and a body may share a name), else a link; (None, None)
/// without a tip.
fn resolve_tip(
    tree: &Tree,
    tip: Option<&str>,
) -> Result<(Option<usize>, Option<usize>), DescriptionError> {
    let Some(name) = tip else {
        return Ok((None, None));
    };
    if let Some(f) = tree.frame_index(name) {
        Ok((tree.link_index(&tree.frames()[f].link), Some(f)))
    } else if let Some(l) = tree.link_index(name) {
        Ok((Some(l), None))
    } else {
        let links = tree.links().iter().map(|l| l.name.as_str());
        let frames = tree.frames().iter().map(|f| f.name.as_str());
        let (n_links, n_frames) = (tree.links().len(), tree.frames().len());
        Err(arm_error(
            tree,
            format!(
                "tip= '{name}' is neither a link nor a frame of it: name the link (a \
                 MuJoCo body) or the frame (a site) that ends the arm; its {n_links} links \
                 and {n_frames} frames, closest first: {}",
                closest_first(name, links.chain(frames), SHOWN)
            ),
        ))
    }
}

/// How many names [`closest_first`] shows before it counts the rest.
const SHOWN: usize = 20;

/// `names` (duplicates once), closest to `name` first (case-insensitive): by
/// the characters of `name` a name lacks in order (|name| − their longest
/// common subsequence: 'panda_tcp' is all in 'panda_hand_tcp'), then by the
/// edit distance, then in their given order; the first `shown` of them
/// quoted, then how many more there are.
fn closest_first<'a>(name: &str, names: impl Iterator<Item = &'a str>, shown: usize) -> String {
    let mut seen: Vec<&str> = Vec::new();
    for n in names {
        if !seen.contains(&n) {
            seen.push(n);
        }
    }
    let wanted = name.to_lowercase();
    let mut ranked: Vec<(usize, usize, usize, &str)> = seen
        .iter()
        .enumerate()
        .map(|(i, n)| {
            let other = n.to_lowercase();
            let lacks = wanted.chars().count() - common_subsequence(&wanted, &other);
            (lacks, edit_distance(&wanted, &other), i, *n)
        })
        .collect();
    ranked.sort();
    let mut out = names_list(ranked.iter().take(shown).map(|r| r.3));
    if ranked.len() > shown {
        out.push_str(&format!(" and {} more", ranked.len() - shown));
    }
    out
}

/// The length of the longest common subsequence of `a` and `b` (characters).
fn common_subsequence(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row = alloc::vec![0usize; b.len() + 1];
    for ca in a.chars() {
        let mut diagonal = 0;
        for (j, cb) in b.iter().enumerate() {
            let above = row[j + 1];
            row[j + 1] = if ca == *cb {
                diagonal + 1
            } else {
                above.max(row[j])
            };
            diagonal = above;
        }
    }
    row[b.len()]
}

/// The Levenshtein distance of `a` and `b` (insertions, deletions and
/// substitutions of characters), one row at a time.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut previous = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let substitute = previous + usize::from(ca != *cb);
            previous = row[j + 1];
            row[j + 1] = substitute.min(previous + 1).min(row[j] + 1);
        }
    }
    row[b.len()]
}

/// The one root link the arm is found from without a tip (rule 3 of
/// (21.2)); an error when the tree has none or several.
fn single_root(tree: &Tree) -> Result<usize, DescriptionError> {
    let roots = tree.roots();
    match roots.as_slice() {
        [root] => Ok(*root),
        [] => Err(arm_error(
            tree,
            "it has no links: it describes no robot".into(),
        )),
        _ => Err(arm_error(
            tree,
            format!(
                "it has {} root links {}: a robot has one; name the arm's last link \
                 with tip=",
                roots.len(),
                names_list(roots.iter().map(|&l| tree.links()[l].name.as_str()))
            ),
        )),
    }
}

impl<'t> Reduction<'t> {
    /// A reduction of `tree` holding nothing yet, with each joint's mimics.
    fn new(tree: &'t Tree) -> Self {
        let joints = tree.joints();
        let mut followers = alloc::vec![Vec::new(); joints.len()];
        for (i, j) in joints.iter().enumerate() {
            if let Some(m) = &j.mimic {
                // (A joint mimicking itself follows none: held as a mistake.)
                if let Some(master) = tree.joint_index(&m.joint).filter(|&k| k != i) {
                    followers[master].push(i);
                }
            }
        }
        Self {
            tree,
            held: BTreeMap::new(),
            followers,
        }
    }

    /// Rule 1 of (21.2): hold what is held whatever the chain: asked,
    /// mimic, coupled, more than one coordinate.
    fn hold_always(&mut self, fix: &[&str]) {
        for (i, j) in self.tree.joints().iter().enumerate() {
            let reason = if fix.contains(&j.name.as_str()) {
                Held::Asked
            } else if let Some(why) = self.tree.mimic_error(i) {
                Held::MimicOfNone { why }
            } else if let Some(m) = &j.mimic {
                Held::Mimic {
                    master: m.joint.clone(),
                }
            } else if let Some(by) = &j.coupled {
                Held::Coupled { by: by.clone() }
            } else if matches!(
                j.kind,
                JointType::Floating | JointType::Planar | JointType::Ball
            ) {
                Held::Free { kind: j.kind }
            } else {
                continue;
            };
            if j.kind != JointType::Fixed {
                self.held.insert(i, reason);
            }
        }
    }

    /// The tip when none is asked for (rule 2 of (21.2)): the first tool
    /// frame (where a force sensor measures) that a revolute joint not held
    /// moves.
    fn tool_frame(&self) -> Option<&'t str> {
        let tree = self.tree;
        let moved = |link: &str| {
            tree.link_index(link).is_some_and(|l| {
                tree.path_to(l).into_iter().any(|j| {
                    matches!(
                        tree.joints()[j].kind,
                        JointType::Revolute | JointType::Continuous
                    ) && !self.held.contains_key(&j)
                })
            })
        };
        tree.frames()
            .iter()
            .find(|f| f.tool && moved(&f.link))
            .map(|f| f.name.as_str())
    }

    /// Rule 2 of (21.2), the arm to the tip's link `l`: the movable joints
    /// on the way not held; every other joint held as not on the way to
    /// `tip`. Errors: a floating, planar or ball joint on the way that
    /// `fix` does not name; no joint left to drive.
    fn path_to_tip(
        &mut self,
        l: usize,
        tip: &str,
        fix: &[&str],
    ) -> Result<Vec<usize>, DescriptionError> {
        let tree = self.tree;
        let joints = tree.joints();
        let path = tree.path_to(l);
        on_the_way(tree, &path, tip, fix)?;
        let arm: Vec<usize> = path
            .into_iter()
            .filter(|&j| joints[j].kind.is_movable() && !self.held.contains_key(&j))
            .collect();
        let on_arm = on_arm(joints.len(), &arm);
        for (i, j) in joints.iter().enumerate() {
            if j.kind != JointType::Fixed && !on_arm[i] && !self.held.contains_key(&i) {
                self.held.insert(
                    i,
                    Held::OffPath {
                        tip: tip.to_string(),
                    },
                );
            }
        }
        if arm.is_empty() {
            return Err(arm_error(
                tree,
                format!(
                    "there is no {} or {} to drive on the way to '{tip}'{}: name a tip \
                     further out",
                    tree.dialect().rotary(),
                    tree.dialect().linear(),
                    held_summary(tree, &self.held, &[])
                ),
            ));
        }
        Ok(arm)
    }
}

/// Per joint of a tree of `n`: whether it is one of `arm`'s.
fn on_arm(n: usize, arm: &[usize]) -> Vec<bool> {
    let mut on_arm = alloc::vec![false; n];
    for &j in arm {
        on_arm[j] = true;
    }
    on_arm
}

/// " (held: 'a' (why), …)" for messages, or "" when nothing is held.
fn held_summary(tree: &Tree, held: &BTreeMap<usize, Held>, skip: &[usize]) -> String {
    let mut out = String::new();
    for (&j, why) in held {
        if skip.contains(&j) || matches!(why, Held::OffPath { .. } | Held::OffChain) {
            continue;
        }
        out.push_str(if out.is_empty() { " (held: " } else { "; " });
        out.push_str(&format!(
            "'{}' {}",
            tree.joints()[j].name,
            why.describe(tree.dialect())
        ));
    }
    if !out.is_empty() {
        out.push(')');
    }
    out
}

/// What hangs below each link of the tree (bottom up, [`Reduction::below`]).
struct Below {
    /// The longest run of joints with a coordinate below the link (the
    /// structure: mimic, prismatic and held ones count).
    depth: Vec<usize>,
    /// Whether a frame hangs anywhere below it.
    frame: Vec<bool>,
    /// Whether a movable joint that mimics nothing does.
    driven: Vec<bool>,
}

/// The longest chains of drivable joints below each link, found bottom up
/// ([`Reduction::longest`]).
struct Longest {
    /// Whether the link is a hand (rule 4 of (21.2)): the arm ends there.
    hand: Vec<bool>,
    /// Per link: the length of the longest chains below it and the last
    /// joint of each.
    best: Vec<(usize, Vec<usize>)>,
}

/// The arm found by the rule of (21.2) from `root`: the joints of the
/// longest chain, base to tip. Marks what it holds in `r.held`.
fn find_chain(r: &mut Reduction<'_>, root: usize) -> Result<Vec<usize>, DescriptionError> {
    let tree = r.tree;
    let order = r.order(root);
    let below = r.below(&order);
    let above = r.hold_grippers(&order, &below);
    let Longest { hand, mut best } = r.longest(&order, &below.depth, &above);
    let (len, ends) = core::mem::take(&mut best[root]);
    if len == 0 {
        return Err(arm_error(
            tree,
            format!(
                "it has no {} to drive{}: name a tip (tip=) to drive a {}",
                tree.dialect().rotary(),
                held_summary(tree, &r.held, &[]),
                tree.dialect().linear()
            ),
        ));
    }
    if ends.len() > 1 {
        let tips = names_list(
            ends.iter()
                .map(|&j| tree.links()[tree.joint_links(j).1].name.as_str()),
        );
        let tips = tips.trim_start_matches('[').trim_end_matches(']');
        return Err(arm_error(
            tree,
            format!(
                "{} serial chains of {len} joints from the root tie for the arm (legs, or two \
                 arms), ending at the links {tips}: name one with tip= or hold the others' \
                 joints with fix=",
                ends.len()
            ),
        ));
    }
    let arm: Vec<usize> = tree
        .path_to(tree.joint_links(ends[0]).1)
        .into_iter()
        .filter(|&j| r.drivable(j))
        .collect();
    r.hold_rest(&order, &hand, &arm);
    Ok(arm)
}

impl Reduction<'_> {
    /// Bottom up over `order` (parents before children): what hangs below
    /// each link, the structure rules 4 and 5 of (21.2) read.
    fn below(&self, order: &[usize]) -> Below {
        let tree = self.tree;
        let joints = tree.joints();
        let nl = tree.links().len();
        let mut depth = alloc::vec![0usize; nl];
        let mut frame_below = alloc::vec![false; nl];
        let mut driven_below = alloc::vec![false; nl];
        for &l in order.iter().rev() {
            frame_below[l] = !tree.link_frames(l).is_empty() || self.is_frame_link(l);
            for &j in tree.child_joints(l) {
                let c = tree.joint_links(j).1;
                let own = usize::from(joints[j].kind.is_movable());
                depth[l] = depth[l].max(own + depth[c]);
                frame_below[l] |= frame_below[c];
                driven_below[l] |= driven_below[c] || (own == 1 && joints[j].mimic.is_none());
            }
        }
        Below {
            depth,
            frame: frame_below,
            driven: driven_below,
        }
    }

    /// Rule 5 of (21.2), top down over `order`: hold a gripper's joints
    /// below an arm joint that is not a gripper's (a drive others mimic, a
    /// jaw beside a tool frame, a gripper's name). Returns per link the
    /// number of drivable joints above it.
    fn hold_grippers(&mut self, order: &[usize], below: &Below) -> Vec<usize> {
        let tree = self.tree;
        let joints = tree.joints();
        let nl = tree.links().len();
        // The arm's joints held so far above each link, and whether one of
        // them is an arm's (not a gripper's).
        let mut above = alloc::vec![0usize; nl];
        let mut arm_above = alloc::vec![false; nl];
        // Per link, the tool frame beside its joints (looked for once).
        let mut beside: Vec<Option<Option<String>>> = alloc::vec![None; nl];
        for &l in order {
            for &j in tree.child_joints(l) {
                let c = tree.joint_links(j).1;
                let word = gripper_word(&joints[j].name);
                if arm_above[l] && self.drivable(j) {
                    let reason = if !self.followers[j].is_empty() && !below.driven[c] {
                        Some(Held::GripperDrive {
                            followers: self.followers[j]
                                .iter()
                                .map(|&f| joints[f].name.clone())
                                .collect(),
                        })
                    } else if let Some(frame) = (!below.frame[c])
                        .then(|| {
                            beside[l]
                                .get_or_insert_with(|| self.frame_beside(l))
                                .clone()
                        })
                        .flatten()
                    {
                        Some(Held::Jaw { frame })
                    } else {
                        word.map(|word| Held::Named { word })
                    };
                    if let Some(reason) = reason {
                        self.held.insert(j, reason);
                    }
                }
                let own = usize::from(self.drivable(j));
                above[c] = above[l] + own;
                arm_above[c] = arm_above[l] || (own == 1 && word.is_none());
            }
        }
        above
    }

    /// Rules 3, 4 and 6 of (21.2), bottom up over `order`: per link the
    /// longest chains of drivable joints below it and where each ends; a
    /// hand (branches shorter than the `above` arm that holds them) ends
    /// the arm.
    fn longest(&self, order: &[usize], depth: &[usize], above: &[usize]) -> Longest {
        let tree = self.tree;
        let joints = tree.joints();
        let nl = tree.links().len();
        let mut hand = alloc::vec![false; nl];
        let mut best = alloc::vec![(0usize, Vec::<usize>::new()); nl];
        for &l in order.iter().rev() {
            let branches: Vec<usize> = tree
                .child_joints(l)
                .iter()
                .map(|&j| usize::from(joints[j].kind.is_movable()) + depth[tree.joint_links(j).1])
                .filter(|&d| d > 0)
                .collect();
            // A hand: two or more branches each shorter than the arm that holds
            // them, or three or more (fingers) none longer.
            let shorter = branches.len() >= 2 && branches.iter().all(|&d| d < above[l]);
            let fingers = branches.len() >= 3 && branches.iter().all(|&d| d <= above[l]);
            if above[l] > 0 && (shorter || fingers) {
                hand[l] = true;
                continue;
            }
            let (mut len, mut ends) = (0usize, Vec::new());
            for &j in tree.child_joints(l) {
                let c = tree.joint_links(j).1;
                let own = usize::from(self.drivable(j));
                let (below, below_ends) = &best[c];
                let this = below + own;
                let these = if *below == 0 {
                    if own == 1 {
                        alloc::vec![j]
                    } else {
                        Vec::new()
                    }
                } else {
                    below_ends.clone()
                };
                if this > len {
                    len = this;
                    ends = these;
                } else if this == len && this > 0 {
                    ends.extend(these);
                }
            }
            best[l] = (len, ends);
        }
        Longest { hand, best }
    }

    /// Rule 6 of (21.2): hold every other joint with a coordinate, in a
    /// hand (the nearest hand link at or above its parent), prismatic, or
    /// off the chain.
    fn hold_rest(&mut self, order: &[usize], hand: &[bool], arm: &[usize]) {
        let tree = self.tree;
        let joints = tree.joints();
        let mut in_hand: Vec<Option<usize>> = alloc::vec![None; tree.links().len()];
        for &l in order {
            let here = if hand[l] { Some(l) } else { in_hand[l] };
            in_hand[l] = here;
            for &j in tree.child_joints(l) {
                in_hand[tree.joint_links(j).1] = here;
            }
        }
        let on_arm = on_arm(joints.len(), arm);
        for (i, j) in joints.iter().enumerate() {
            if j.kind == JointType::Fixed || on_arm[i] || self.held.contains_key(&i) {
                continue;
            }
            let reason = match in_hand[tree.joint_links(i).0] {
                Some(l) => Held::Hand {
                    link: tree.links()[l].name.clone(),
                },
                None if j.kind == JointType::Prismatic => Held::Prismatic,
                None => Held::OffChain,
            };
            self.held.insert(i, reason);
        }
    }
}

/// The value joint `j` is held at: its offset, or for a mimic joint the
/// multiplier times its master's offset plus its own.
fn held_value(tree: &Tree, j: usize) -> f64 {
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

fn config(tree: &Tree, e: Error) -> DescriptionError {
    DescriptionError::new(ErrorKind::Value, format!("{}: {e}", tree.source()))
}

/// The frame of joint `j`'s child link in its parent link's frame, with the
/// joint at `value` (fixed joints: their origin).
fn joint_frame(tree: &Tree, j: usize, value: f64) -> Result<Frame, DescriptionError> {
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
struct Fold<'t> {
    tree: &'t Tree,
    /// Per joint: whether it is an arm joint.
    on_arm: Vec<bool>,
    /// The first link folded into a body whose inertia no rigid body has.
    unphysical: core::cell::RefCell<Option<DescriptionError>>,
}

impl Fold<'_> {
    /// The value joint `j` is folded at: an arm joint's offset, a held
    /// joint's held value.
    fn value(&self, j: usize) -> f64 {
        if self.on_arm[j] {
            self.tree.joints()[j].offset
        } else {
            held_value(self.tree, j)
        }
    }

    /// The chain to `tip_link` (SPEC §16): fixed and held joints fold into
    /// the next arm joint's origin; what is left after the last one, and
    /// the frame `tip_frame`, is the tip's origin.
    fn chain(
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
    fn links(&self, a: usize) -> Vec<usize> {
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
    fn body(&self, a: usize) -> Result<(Inertial, Lifted), DescriptionError> {
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
fn physical(tree: &Tree, l: usize, i: &[[f64; 3]; 3]) -> Result<(), DescriptionError> {
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
fn arm_joint(tree: &Tree, j: usize) -> ArmJoint {
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
fn build(
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
