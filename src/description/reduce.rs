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

mod arm;
mod fold;
mod names;
pub use arm::*;
use fold::*;
use names::*;

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
            let link_name = tree.links()[end].name.clone();
            // The joints the rule passes on its way are the arm's business
            // too (a floating one was held silently here, refused with the
            // same tip given).
            on_the_way(tree, &tree.path_to(end), &link_name, fix)?;
            // Rule 7: a frame the file's author put on that link (a MuJoCo
            // site: `grasp`, `end_effector`) is the tool point, the first
            // in file order; else the link itself.
            if let Some(f) = tree.frames().iter().position(|f| f.link == link_name) {
                let tip_name = tree.frames()[f].name.clone();
                return build(&r, root, arm, tip_name, Some(end), Some(f));
            }
            (root, arm, link_name)
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
