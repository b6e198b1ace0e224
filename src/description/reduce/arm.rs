//! The reduction's result: the arm ([`Arm`]), its joints ([`ArmJoint`]) and
//! the joints held, each with why ([`Held`], [`HeldJoint`]).

use super::*;

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
