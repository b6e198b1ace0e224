//! The checks of a tree's construction: every value finite, names unique,
//! every joint between two known links, one parent per link and no loop,
//! frames on known links.

use super::*;

pub(super) fn structure(source: &str, message: String) -> DescriptionError {
    DescriptionError::new(ErrorKind::Structure, format!("{source}: {message}"))
}

pub(super) fn finite_or(
    source: &str,
    what: &str,
    name: &str,
    v: &[f64],
) -> Result<(), DescriptionError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(DescriptionError::new(
            ErrorKind::Value,
            format!("{source}: {what} of {name} is not finite ({v:?}): give finite numbers"),
        ))
    }
}

pub(super) fn origin_ok(
    source: &str,
    what: &str,
    name: &str,
    o: &Origin,
) -> Result<(), DescriptionError> {
    match o {
        Origin::XyzRpy(a, b) => {
            finite_or(source, what, name, a)?;
            finite_or(source, what, name, b)
        }
        Origin::PosQuat(a, q) => {
            finite_or(source, what, name, a)?;
            finite_or(source, what, name, q)?;
            if q.iter().all(|&x| x == 0.0) {
                return Err(DescriptionError::new(
                    ErrorKind::Value,
                    format!("{source}: {what} of {name} has a zero quaternion: give a rotation"),
                ));
            }
            Ok(())
        }
        Origin::Matrix(t) => {
            finite_or(source, what, name, &t.translation)?;
            finite_or(source, what, name, t.rotation.as_flattened())
        }
    }
}

/// Names to their indices.
pub(super) type Index = BTreeMap<String, usize>;

/// The links by name (SPEC (21.1)): unique names, each inertial finite with
/// a mass ≥ 0.
pub(super) fn index_links(source: &str, links: &[Link]) -> Result<Index, DescriptionError> {
    let mut link_index = BTreeMap::new();
    for (i, l) in links.iter().enumerate() {
        if link_index.insert(l.name.clone(), i).is_some() {
            return Err(structure(
                source,
                format!(
                    "two links are named '{}': give each link its own name",
                    l.name
                ),
            ));
        }
        let what = format!("link '{}'", l.name);
        if let Some(i) = &l.inertial {
            origin_ok(source, "the inertial origin", &what, &i.origin)?;
            finite_or(source, "the mass", &what, &[i.mass])?;
            finite_or(source, "the gravity compensation", &what, &[i.gravcomp])?;
            finite_or(source, "the inertia", &what, i.inertia.as_flattened())?;
            if i.mass < 0.0 {
                return Err(DescriptionError::new(
                    ErrorKind::Value,
                    format!(
                        "{source}: link '{}' has the mass {} kg: a mass is ≥ 0",
                        l.name, i.mass
                    ),
                ));
            }
        }
    }
    Ok(link_index)
}

/// The joints as edges between links (SPEC (21.1)), built by [`Edges::of`].
pub(super) struct Edges {
    pub(super) joint_index: Index,
    /// Per link: the joint that carries it.
    pub(super) parent_joint: Vec<Option<usize>>,
    /// Per link: the joints that hang from it, in order.
    pub(super) children: Vec<Vec<usize>>,
    /// Per joint: its parent and child links.
    pub(super) ends: Vec<(usize, usize)>,
}

impl Edges {
    /// The edges of `joints` between the links of `link_index`, each joint
    /// checked in order: a unique name, declared parent and child links, a
    /// child no other joint carries, then its numbers ([`check_joint`]).
    pub(super) fn of(
        source: &str,
        link_index: &Index,
        joints: &[TreeJoint],
    ) -> Result<Self, DescriptionError> {
        let n = link_index.len();
        let mut e = Self {
            joint_index: BTreeMap::new(),
            parent_joint: alloc::vec![None; n],
            children: alloc::vec![Vec::new(); n],
            ends: Vec::with_capacity(joints.len()),
        };
        for (i, j) in joints.iter().enumerate() {
            if e.joint_index.insert(j.name.clone(), i).is_some() {
                return Err(structure(
                    source,
                    format!(
                        "two joints are named '{}': give each joint its own name",
                        j.name
                    ),
                ));
            }
            let end = |role: &str, link: &str| {
                link_index.get(link).copied().ok_or_else(|| {
                    structure(
                        source,
                        format!(
                            "joint '{}' names the {role} link '{link}', which is not declared \
                             (a missing link): declare it or correct the joint's <{role}>",
                            j.name
                        ),
                    )
                })
            };
            let (p, c) = (end("parent", &j.parent)?, end("child", &j.child)?);
            if let Some(other) = e.parent_joint[c] {
                let other: &TreeJoint = &joints[other];
                return Err(structure(
                    source,
                    format!(
                        "link '{}' is the child of two joints ('{}' and '{}'): a kinematic loop, \
                         which a tree cannot hold; remove one of them",
                        j.child, other.name, j.name
                    ),
                ));
            }
            e.parent_joint[c] = Some(i);
            e.children[p].push(i);
            e.ends.push((p, c));
            check_joint(source, j)?;
        }
        Ok(e)
    }
}

/// Joint `j`'s numbers: a finite origin, axis and offset; damping,
/// friction and armature finite and ≥ 0; lower ≤ upper.
pub(super) fn check_joint(source: &str, j: &TreeJoint) -> Result<(), DescriptionError> {
    let what = format!("joint '{}'", j.name);
    origin_ok(source, "the origin", &what, &j.origin)?;
    finite_or(source, "the axis", &what, &j.axis)?;
    finite_or(source, "the offset", &what, &[j.offset])?;
    for (v, q) in [
        (j.damping, "damping"),
        (j.friction, "friction"),
        (j.armature, "armature"),
    ] {
        if !(v >= 0.0 && v.is_finite()) {
            return Err(DescriptionError::new(
                ErrorKind::Value,
                format!(
                    "{source}: joint '{}' has the {q} {v}: it must be finite and ≥ 0",
                    j.name
                ),
            ));
        }
    }
    if j.lower.is_nan() || j.upper.is_nan() || j.lower > j.upper {
        return Err(DescriptionError::new(
            ErrorKind::Value,
            format!(
                "{source}: joint '{}' has the limits [{}, {}]: give lower ≤ upper",
                j.name, j.lower, j.upper
            ),
        ));
    }
    Ok(())
}

/// Every link's way up ends at a root rather than running in a circle:
/// each link is walked once (0 not yet, 1 on this walk, 2 ends at a root).
pub(super) fn check_no_loop(
    source: &str,
    links: &[Link],
    parent_joint: &[Option<usize>],
    ends: &[(usize, usize)],
) -> Result<(), DescriptionError> {
    let mut seen = alloc::vec![0u8; links.len()];
    for start in 0..links.len() {
        let mut link = start;
        while seen[link] == 0 {
            seen[link] = 1;
            match parent_joint[link] {
                Some(j) => link = ends[j].0,
                None => break,
            }
        }
        if seen[link] == 1 && parent_joint[link].is_some() {
            return Err(structure(
                source,
                format!(
                    "the joints form a loop through the link '{}': a tree cannot hold it; \
                     remove a joint of the loop",
                    links[link].name
                ),
            ));
        }
        let mut link = start;
        while seen[link] == 1 {
            seen[link] = 2;
            if let Some(j) = parent_joint[link] {
                link = ends[j].0;
            }
        }
    }
    Ok(())
}

/// The frames by name and per link (SPEC (21.1)): unique names, on a
/// declared link, a finite origin.
pub(super) fn index_frames(
    source: &str,
    link_index: &Index,
    frames: &[NamedFrame],
) -> Result<(Index, Vec<Vec<usize>>), DescriptionError> {
    let mut frame_index = BTreeMap::new();
    let mut link_frames = alloc::vec![Vec::new(); link_index.len()];
    for (i, f) in frames.iter().enumerate() {
        if frame_index.insert(f.name.clone(), i).is_some() {
            return Err(structure(
                source,
                format!("two frames are named '{}': give each its own name", f.name),
            ));
        }
        let l = link_index.get(&f.link).copied().ok_or_else(|| {
            structure(
                source,
                format!(
                    "frame '{}' is on the link '{}', which is not declared",
                    f.name, f.link
                ),
            )
        })?;
        origin_ok(
            source,
            "the origin",
            &format!("frame '{}'", f.name),
            &f.origin,
        )?;
        link_frames[l].push(i);
    }
    Ok((frame_index, link_frames))
}
