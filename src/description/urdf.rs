//! URDF files to the [`Tree`] (feature `urdf`), SPEC (21.1), through the
//! maintained `urdf-rs` crate; and the reduced URDF an [`Arm`] leaves for
//! MuJoCo's compiler.
//!
//! What is read: each link's `<inertial>`; each joint's type, `<origin xyz
//! rpy>`, `<axis>` (default (1, 0, 0)), `<limit lower upper effort
//! velocity>`, `<dynamics damping friction>` and `<mimic joint multiplier
//! offset>`. A `continuous` joint has no limits; so has a revolute or
//! prismatic joint whose limits leave no range (lower ≥ upper, "0 0" in
//! many exported files), and a revolute one is then continuous. An effort
//! or velocity of zero (or none) is NaN: not stated. Meshes, `<gazebo>`,
//! `<transmission>` and the rest are not needed and not read.
//!
//! A URDF with xacro markup (an element `<xacro:…>`, an attribute with
//! `${…}` or `$(…)`; comments and a leftover `xmlns:xacro` do not count) is
//! refused ([`ErrorKind::Xacro`]) with the one command that expands it.
//! The document is read by the XML reader urdf-rs uses, its links' visual
//! and collision geometry dropped (no mesh is needed, and a mesh element
//! urdf-rs would refuse is no reason to refuse an arm), then by urdf-rs.

use super::error::{DescriptionError, ErrorKind};
use super::reduce::{Arm, ArmJoint};
use super::tree::{JointType, Link, LinkInertial, Mimic, Origin, Tree, TreeJoint};
use std::fmt::Write as _;
use std::format;
use std::path::Path;
use std::string::{String, ToString};
use std::vec::Vec;

mod stream;
mod write;
use stream::*;
pub use write::*;

/// The xacro namespace.
const XACRO_NS: &str = "http://www.ros.org/wiki/xacro";

/// The tree of the URDF file at `path` (labelled by its file name in later
/// messages).
///
/// Errors: the file cannot be read ([`ErrorKind::Io`]), is xacro
/// ([`ErrorKind::Xacro`]), is not a URDF the parser reads
/// ([`ErrorKind::Parse`], naming the element), or its tree is not one
/// ([`Tree::new`]).
pub fn read_file(path: impl AsRef<Path>) -> Result<Tree, DescriptionError> {
    read_file_with(path, &mut || true)
}

/// [`read_file`], asking `go_on` between two pieces of the work (at most
/// [`CHUNK_BYTES`] of text or [`BATCH_ELEMENTS`] elements apart): false
/// stops it ([`ErrorKind::Stopped`]). A front's Ctrl-C.
pub fn read_file_with(
    path: impl AsRef<Path>,
    go_on: &mut GoOn<'_>,
) -> Result<Tree, DescriptionError> {
    let path = path.as_ref();
    let text = read_text(path, "URDF").map_err(|e| {
        DescriptionError::new(
            ErrorKind::Io,
            format!(
                "cannot read the URDF '{}': {e}: give the path of a URDF file",
                shown_path(path)
            ),
        )
    })?;
    let label = path
        .file_name()
        .map_or_else(|| shown_path(path), |n| n.to_string_lossy().into());
    read(&text, &format!("URDF '{label}'"), &shown_path(path), go_on)
}

/// What a reading asks between two pieces of its work: whether to go on.
pub type GoOn<'a> = dyn FnMut() -> bool + 'a;

/// Bytes of text the XML reader is given at a time (a reading asks its
/// [`GoOn`] after each).
pub const CHUNK_BYTES: usize = 64 << 10;

/// Links and joints handed to urdf-rs at a time (a reading asks its
/// [`GoOn`] after each batch): the elements of a document are never all in
/// memory at once, and each is read once, so a reading is linear in the
/// document's size.
pub const BATCH_ELEMENTS: usize = 256;

/// A path as messages show it: whole, unless it is long or holds a line
/// break (text given where a path was expected): then its start and its
/// length.
pub fn shown_path(path: &Path) -> String {
    let s = path.display().to_string();
    if s.chars().count() <= 200 && !s.contains(['\n', '\r']) {
        return s;
    }
    let start: String = s
        .chars()
        .take(60)
        .take_while(|c| *c != '\n' && *c != '\r')
        .collect();
    format!("{start}… ({} characters)", s.chars().count())
}

/// Whether `source` is description text (its first character, after a
/// byte-order mark and white space, a `<`) rather than a path.
pub fn is_text(source: &str) -> bool {
    source
        .strip_prefix('\u{feff}')
        .unwrap_or(source)
        .trim_start()
        .starts_with('<')
}

/// The largest description file read (bytes): a robot's URDF or MJCF is a
/// few MB at most; a device or a mistaken path (`/dev/zero`, a disk image)
/// would otherwise be read until memory runs out.
pub const MAX_FILE_BYTES: u64 = 32 << 20;

/// The deepest element nesting read: a URDF nests 5 levels, a robot's MJCF
/// a few tens; the XML reader's elements are built and dropped recursively,
/// so a document nested 100 000 deep would overflow the stack.
pub const MAX_DEPTH: usize = 1000;

/// The text of the file at `path` (what: "URDF", "description"): a regular
/// file of at most [`MAX_FILE_BYTES`], UTF-8; the error says which of these
/// failed (to follow "cannot read 'PATH': ").
pub fn read_text(path: &Path, what: &str) -> Result<String, String> {
    use std::io::Read as _;
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    if meta.is_dir() {
        return Err("it is a directory".into());
    }
    if !meta.is_file() {
        return Err(format!(
            "it is not a regular file (a device or a pipe), not a {what}"
        ));
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(format!(
            "it has {} bytes; a {what} file has at most {MAX_FILE_BYTES}",
            meta.len()
        ));
    }
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let mut text = String::new();
    file.take(MAX_FILE_BYTES + 1)
        .read_to_string(&mut text)
        .map_err(|e| e.to_string())?;
    if text.len() as u64 > MAX_FILE_BYTES {
        return Err(format!("it grew beyond {MAX_FILE_BYTES} bytes while read"));
    }
    Ok(text)
}

/// How deeply the elements of `text` nest, counting no further than
/// `MAX_DEPTH + 1` (comments, CDATA, processing instructions, declarations
/// and quoted attribute values are skipped). Linear in the text.
fn nesting(text: &str) -> usize {
    let b = text.as_bytes();
    let skip_to = |from: usize, end: &[u8]| {
        b[from..]
            .windows(end.len())
            .position(|w| w == end)
            .map_or(b.len(), |p| from + p + end.len())
    };
    let (mut i, mut depth, mut deepest) = (0, 0usize, 0usize);
    while i < b.len() {
        if b[i] != b'<' {
            i += 1;
            continue;
        }
        let rest = &b[i..];
        if rest.starts_with(b"<!--") {
            i = skip_to(i + 4, b"-->");
        } else if rest.starts_with(b"<![CDATA[") {
            i = skip_to(i + 9, b"]]>");
        } else if rest.starts_with(b"<?") {
            i = skip_to(i + 2, b"?>");
        } else if rest.starts_with(b"<!") || rest.starts_with(b"</") {
            depth = depth.saturating_sub(usize::from(rest.starts_with(b"</")));
            i = skip_to(i + 2, b">");
        } else {
            // A start tag: to its '>' outside quotes; "/>" closes it at once.
            let mut j = i + 1;
            let mut quote = 0u8;
            while j < b.len() && (quote != 0 || b[j] != b'>') {
                if quote == 0 && (b[j] == b'"' || b[j] == b'\'') {
                    quote = b[j];
                } else if b[j] == quote {
                    quote = 0;
                }
                j += 1;
            }
            if !(j < b.len() && b[j - 1] == b'/') {
                depth += 1;
                deepest = deepest.max(depth);
                if deepest > MAX_DEPTH {
                    return deepest;
                }
            }
            i = j + 1;
        }
    }
    deepest
}

/// The tree of the URDF `text` (labelled "URDF text" in messages).
pub fn read_str(text: &str) -> Result<Tree, DescriptionError> {
    read(text, "URDF text", "the URDF text", &mut || true)
}

/// The tree of the URDF `text`, labelled `label` in messages (e.g. "xacro
/// 'arm.xacro'" for a file a front expanded).
pub fn read_str_as(text: &str, label: &str) -> Result<Tree, DescriptionError> {
    read(text, label, label, &mut || true)
}

/// [`read_str`] (`label` None) or [`read_str_as`], asking `go_on` between
/// two pieces of the work, as [`read_file_with`] does.
pub fn read_str_with(
    text: &str,
    label: Option<&str>,
    go_on: &mut GoOn<'_>,
) -> Result<Tree, DescriptionError> {
    match label {
        Some(l) => read(text, l, l, go_on),
        None => read(text, "URDF text", "the URDF text", go_on),
    }
}

/// What a description's text is, by its root element and its markup:
/// `"mjcf"` (`<mujoco>`), `"mjcf-fragment"` (a `<mujocoinclude>`, or a
/// `<mujoco>` whose bodies are not in a `<worldbody>`: a file other MJCF
/// files include), `"xacro"` (a `<robot>` with xacro markup), `"urdf"` (a
/// `<robot>`), or `"unknown"` (not XML before its root element, nested too
/// deep, another root). The rest of a `<robot>` is read only where its text
/// could hold xacro markup; its validity is the reader's to judge.
pub fn kind_of(text: &str) -> &'static str {
    kind_of_with(text, &mut || true).unwrap_or("unknown")
}

/// [`kind_of`], asking `go_on` between two pieces of the work: an error
/// ([`ErrorKind::Stopped`]) if it says stop.
pub fn kind_of_with(text: &str, go_on: &mut GoOn<'_>) -> Result<&'static str, DescriptionError> {
    if nesting(text) > MAX_DEPTH {
        return Ok("unknown");
    }
    let text = without_bom(text);
    let scan = might_be_xacro(text);
    let kind = core::cell::Cell::new("unknown");
    let mut bodies = Bodies::default();
    let found = stream(
        text,
        go_on,
        |tag| {
            kind.set(match tag.name.as_str() {
                "mujoco" => "mjcf",
                "mujocoinclude" => "mjcf-fragment",
                "robot" => "urdf",
                _ => "unknown",
            });
            // Read on where the rest decides: an MJCF's bodies, a URDF's markup.
            Ok(kind.get() == "mjcf" || (kind.get() == "urdf" && scan))
        },
        |root| {
            if kind.get() == "mjcf" {
                bodies.add(&root);
                return Ok(());
            }
            match xacro_markup(&root) {
                Some(what) => Err(DescriptionError::new(ErrorKind::Xacro, what)),
                None => Ok(()),
            }
        },
    );
    match found {
        Ok(()) if kind.get() == "mjcf" && bodies.fragment() => Ok("mjcf-fragment"),
        Ok(()) => Ok(kind.get()),
        Err(Streamed::Described(e)) if e.kind() == ErrorKind::Xacro => Ok("xacro"),
        Err(Streamed::Described(e)) => Err(e),
        Err(Streamed::Stopped) => Err(stopped()),
        Err(Streamed::NotXml(_)) if text.contains("<xacro:") => Ok("xacro"),
        Err(Streamed::NotXml(_)) => Ok(kind.get()),
    }
}

/// The first xacro markup in the document: an element in the xacro
/// namespace, or an attribute with `${…}` or `$(…)` (comments do not count).
fn xacro_markup(root: &xml::Element) -> Option<String> {
    // In the document's order: the first markup a reader meets.
    let mut todo = std::vec![root];
    while let Some(e) = todo.pop() {
        if e.ns.as_deref() == Some(XACRO_NS) {
            return Some(format!("the element <xacro:{}>", e.name));
        }
        // By name: the message is the same on every run.
        let mut attributes: Vec<(&String, &String)> =
            e.attributes.iter().map(|((n, _), v)| (n, v)).collect();
        attributes.sort();
        for (name, value) in attributes {
            if value.contains("${") || value.contains("$(") {
                return Some(format!("the expression {name}=\"{value}\" in <{}>", e.name));
            }
        }
        for c in e.children.iter().rev() {
            if let xml::Xml::ElementNode(child) = c {
                todo.push(child);
            }
        }
    }
    None
}

fn read(
    text: &str,
    source: &str,
    shown: &str,
    go_on: &mut GoOn<'_>,
) -> Result<Tree, DescriptionError> {
    let errors = ReadErrors { source, shown };
    let text = without_bom(text);
    let scan = might_be_xacro(text);
    // Each batch's elements as the tree's at once (urdf-rs's own are
    // dropped), a value error kept until the whole document has parsed.
    let mut name: Option<String> = None;
    let (mut links, mut joints) = (Vec::new(), Vec::new());
    let mut value_error = None;
    let mut mjcf = false;
    let read = stream(
        text,
        go_on,
        |tag| {
            mjcf = matches!(tag.name.as_str(), "mujoco" | "mujocoinclude");
            errors.robot_root(tag).map(|()| true)
        },
        |mut root| {
            if scan {
                if let Some(what) = xacro_markup(&root) {
                    return Err(errors.xacro(&what));
                }
            }
            strip_for_arm(&mut root);
            let inertial = with_inertial(&root);
            let part = errors.parse_root(&root)?;
            drop(root);
            links.extend(part.links.iter().map(|l| link_of(l, &inertial)));
            if value_error.is_none() {
                value_error = limits_ok(&part, source).err();
            }
            joints.extend(part.joints.iter().map(joint_of));
            name.get_or_insert(part.name);
            Ok(())
        },
    );
    match read {
        Ok(()) => {}
        Err(Streamed::Described(e)) if mjcf => {
            return match mjcf_fragment(text, go_on) {
                Ok(true) => Err(errors.mjcf_fragment()),
                Err(Streamed::Stopped) => Err(stopped()),
                _ => Err(e),
            }
        }
        Err(Streamed::Described(e)) => return Err(e),
        Err(Streamed::Stopped) => return Err(stopped()),
        Err(Streamed::NotXml(_)) if text.contains("<xacro:") => {
            return Err(errors.xacro("xacro elements <xacro:…>"))
        }
        Err(Streamed::NotXml(e)) => return Err(errors.parse_error(&e)),
    }
    // The root closed: at least one batch was read.
    let name = name.ok_or_else(|| errors.parse_error("it has no root element"))?;
    if let Some(e) = value_error {
        return Err(e);
    }
    Tree::new(source, &name, links, joints, Vec::new()).map(Tree::balanced_inertias)
}

/// The errors of one reading, naming `source` (the label of later
/// messages) and `shown` (the path or text as the user gave it).
struct ReadErrors<'a> {
    source: &'a str,
    shown: &'a str,
}

impl ReadErrors<'_> {
    /// Xacro markup (`what`), with the command that expands it.
    fn xacro(&self, what: &str) -> DescriptionError {
        let shown = self.shown;
        let file = if shown.starts_with("the ") || shown.starts_with("xacro ") {
            "FILE.xacro"
        } else {
            shown
        };
        DescriptionError::new(
            ErrorKind::Xacro,
            format!(
                "{} is xacro, not a URDF (it has {what}): expand it into a URDF first \
                 with `xacro {file} -o robot.urdf` (the xacro package: pip install xacro)",
                self.source
            ),
        )
    }

    /// Not a URDF the parser reads: `e`, and where the format is described.
    fn parse_error(&self, e: &str) -> DescriptionError {
        DescriptionError::new(
            ErrorKind::Parse,
            format!(
                "cannot read {} as a URDF: {e}; correct it against the URDF format \
                 (http://wiki.ros.org/urdf/XML)",
                self.shown
            ),
        )
    }

    /// An MJCF fragment given as a URDF.
    fn mjcf_fragment(&self) -> DescriptionError {
        DescriptionError::new(
            ErrorKind::Parse,
            format!(
                "{} is an MJCF fragment (its bodies are not in a <worldbody>: a file that \
                 other MJCF files include), not a URDF: load the scene that includes it",
                self.shown
            ),
        )
    }

    /// The document's root element is a `<robot>`: else an MJCF or another
    /// root.
    fn robot_root(&self, root: &xml::StartTag) -> Result<(), DescriptionError> {
        if root.name == "mujoco" {
            return Err(DescriptionError::new(
                ErrorKind::Parse,
                format!(
                    "{} is an MJCF (its root element is <mujoco>), not a URDF: read it \
                     through MuJoCo's compiler (Python: give its path to adaptimp, which \
                     compiles it)",
                    self.shown
                ),
            ));
        }
        if root.name != "robot" {
            return Err(
                self.parse_error(&format!("its root element is <{}>, not <robot>", root.name))
            );
        }
        Ok(())
    }

    /// urdf-rs's robot of the (stripped) document `root`, written back and
    /// parsed; on an error, the first element it cannot read named.
    fn parse_root(&self, root: &xml::Element) -> Result<urdf_rs::Robot, DescriptionError> {
        let bare = std::panic::catch_unwind(|| format!("{root}"))
            .map_err(|_| self.parse_error("its namespaces cannot be written back"))?;
        parse(&bare).map_err(|e| {
            // Writing an element alone can meet a prefix bound on the root: no
            // pointer then, rather than a panic.
            let at = std::panic::catch_unwind(|| first_bad_element(root))
                .ok()
                .flatten()
                .map_or_else(String::new, |el| format!("{el}: "));
            self.parse_error(&format!("{at}{e}"))
        })
    }
}

/// What the arm needs of the document: no geometry or material (a mesh or
/// a texture urdf-rs cannot read is no reason to refuse an arm; urdf-rs
/// itself drops <gazebo> and <transmission>), and a `<limit>` without its
/// effort or velocity stating none (many files omit them; urdf-rs wants
/// both).
fn strip_for_arm(root: &mut xml::Element) {
    root.children
        .retain(|c| !matches!(c, xml::Xml::ElementNode(e) if e.name == "material"));
    for child in &mut root.children {
        let xml::Xml::ElementNode(e) = child else {
            continue;
        };
        if e.name == "link" {
            e.children.retain(|c| {
                !matches!(c, xml::Xml::ElementNode(g) if g.name == "visual" || g.name == "collision")
            });
        } else if e.name == "joint" {
            for c in &mut e.children {
                if let xml::Xml::ElementNode(limit) = c {
                    if limit.name == "limit" {
                        for key in ["effort", "velocity"] {
                            if limit.get_attribute(key, None).is_none() {
                                limit.set_attribute(key.into(), None, "0".into());
                            }
                        }
                    }
                }
            }
        }
    }
}

/// The names of the links whose element has an `<inertial>` (urdf-rs
/// gives every link one).
fn with_inertial(root: &xml::Element) -> std::collections::BTreeSet<String> {
    root.children
        .iter()
        .filter_map(|c| match c {
            xml::Xml::ElementNode(e)
                if e.name == "link" && e.get_child("inertial", None).is_some() =>
            {
                e.get_attribute("name", None).map(String::from)
            }
            _ => None,
        })
        .collect()
}

/// urdf-rs's reading, with a panic inside it (a malformed document it does
/// not expect) turned into an error.
fn parse(text: &str) -> Result<urdf_rs::Robot, String> {
    match std::panic::catch_unwind(|| urdf_rs::read_from_string(text)) {
        Ok(Ok(robot)) => Ok(robot),
        Ok(Err(e)) => Err(e.to_string()),
        Err(_) => Err("the parser could not read it".into()),
    }
}

/// The first `<link>` or `<joint>` that urdf-rs cannot read on its own
/// (its kind and name), to point at it.
fn first_bad_element(root: &xml::Element) -> Option<String> {
    let mut links = String::new();
    for child in &root.children {
        if let xml::Xml::ElementNode(e) = child {
            if e.name == "link" {
                let _ = write!(links, "{e}");
            }
        }
    }
    for child in &root.children {
        let xml::Xml::ElementNode(e) = child else {
            continue;
        };
        if e.name != "link" && e.name != "joint" {
            continue;
        }
        let body = if e.name == "link" {
            format!("<robot name=\"r\">{e}</robot>")
        } else {
            format!("<robot name=\"r\">{links}{e}</robot>")
        };
        if parse(&body).is_err() {
            let name = e.get_attribute("name", None).unwrap_or("");
            let inner = bad_vector(e).map_or_else(String::new, |v| format!(": {v}"));
            return Some(format!("<{} name=\"{name}\">{inner}", e.name));
        }
    }
    None
}

/// The first element below `e` whose vector attribute (`xyz`, `rpy`) does
/// not hold three numbers (`<axis xyz="0 1">`), to name beside its joint.
fn bad_vector(e: &xml::Element) -> Option<String> {
    let mut todo = std::vec![e];
    while let Some(el) = todo.pop() {
        for key in ["xyz", "rpy"] {
            if let Some(v) = el.get_attribute(key, None) {
                if v.split_whitespace().count() != 3 {
                    return Some(format!(
                        "<{} {key}=\"{v}\"> (three numbers, x y z)",
                        el.name
                    ));
                }
            }
        }
        for c in el.children.iter().rev() {
            if let xml::Xml::ElementNode(child) = c {
                todo.push(child);
            }
        }
    }
    None
}

fn origin(p: &urdf_rs::Pose) -> Origin {
    Origin::XyzRpy(*p.xyz, *p.rpy)
}

fn stated(v: f64) -> f64 {
    if v > 0.0 && v.is_finite() {
        v
    } else {
        f64::NAN
    }
}

/// The parsed joints' limits are numbers, efforts and speeds ≥ 0.
fn limits_ok(robot: &urdf_rs::Robot, source: &str) -> Result<(), DescriptionError> {
    // A limit that is not a number, or a negative effort or speed, is a
    // mistake in the file, not "no limit" (NaN made a revolute joint
    // continuous, and a negative effort "none stated").
    for j in &robot.joints {
        let l = &j.limit;
        for (v, what, signed) in [
            (l.lower, "lower", true),
            (l.upper, "upper", true),
            (l.effort, "effort", false),
            (l.velocity, "velocity", false),
        ] {
            if v.is_nan() || (!signed && v < 0.0) {
                return Err(DescriptionError::new(
                    ErrorKind::Value,
                    format!(
                        "{source}: joint '{}' has <limit {what}=\"{v}\">: give a number{}",
                        j.name,
                        if signed {
                            ""
                        } else {
                            " ≥ 0 (0: none stated)"
                        }
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// A parsed link: its inertial if its element has one (`with_inertial`;
/// urdf-rs gives every link one).
fn link_of(l: &urdf_rs::Link, with_inertial: &std::collections::BTreeSet<String>) -> Link {
    let i = &l.inertial.inertia;
    Link {
        name: l.name.clone(),
        inertial: with_inertial.contains(&l.name).then(|| LinkInertial {
            mass: l.inertial.mass.value,
            origin: origin(&l.inertial.origin),
            inertia: [
                [i.ixx, i.ixy, i.ixz],
                [i.ixy, i.iyy, i.iyz],
                [i.ixz, i.iyz, i.izz],
            ],
            gravcomp: 0.0,
        }),
    }
}

/// A parsed joint (SPEC (21.1), URDF): a revolute joint without a range is
/// continuous; limits only where they leave a range; an effort or velocity
/// of a movable joint NaN unless stated; its dynamics and mimic.
fn joint_of(j: &urdf_rs::Joint) -> TreeJoint {
    let mut kind = match j.joint_type {
        urdf_rs::JointType::Fixed => JointType::Fixed,
        urdf_rs::JointType::Revolute => JointType::Revolute,
        urdf_rs::JointType::Continuous => JointType::Continuous,
        urdf_rs::JointType::Prismatic => JointType::Prismatic,
        urdf_rs::JointType::Floating => JointType::Floating,
        urdf_rs::JointType::Planar => JointType::Planar,
        urdf_rs::JointType::Spherical => JointType::Ball,
    };
    let mut joint = TreeJoint::new(
        &j.name,
        kind,
        &j.parent.link,
        &j.child.link,
        origin(&j.origin),
    );
    joint.axis = *j.axis.xyz;
    let (lo, hi) = (j.limit.lower, j.limit.upper);
    let ranged = lo < hi;
    if kind == JointType::Revolute && !ranged {
        kind = JointType::Continuous;
    }
    joint.kind = kind;
    if matches!(kind, JointType::Revolute | JointType::Prismatic) && ranged {
        joint.lower = lo;
        joint.upper = hi;
    }
    if kind.is_movable() {
        joint.effort = stated(j.limit.effort);
        joint.velocity = stated(j.limit.velocity);
    }
    if let Some(d) = &j.dynamics {
        joint.damping = d.damping;
        joint.friction = d.friction;
    }
    joint.mimic = j.mimic.as_ref().map(|m| Mimic {
        joint: m.joint.clone(),
        multiplier: m.multiplier.unwrap_or(1.0),
        offset: m.offset.unwrap_or(0.0),
    });
    joint
}
