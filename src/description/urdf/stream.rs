//! The document read a piece at a time (64 KiB of text, 256 elements to the
//! XML reader), asking between pieces whether to go on: an MJCF's bodies
//! found, or the URDF's elements built, in linear memory.

use super::*;

/// Where an MJCF's bodies are, over the batches of its root's children: in
/// its `<worldbody>`, or loose under the root (a fragment, a file that task
/// scenes include inside theirs; MuJoCo compiles it to an empty world).
#[derive(Default)]
pub(super) struct Bodies {
    pub(super) in_world: bool,
    pub(super) loose: bool,
}

impl Bodies {
    pub(super) fn add(&mut self, root: &xml::Element) {
        fn elements(e: &xml::Element) -> impl Iterator<Item = &xml::Element> {
            e.children.iter().filter_map(|c| match c {
                xml::Xml::ElementNode(e) => Some(e),
                _ => None,
            })
        }
        fn has_body(e: &xml::Element) -> bool {
            elements(e).any(|c| c.name == "body" || has_body(c))
        }
        self.in_world |= elements(root)
            .filter(|c| c.name == "worldbody")
            .any(has_body);
        self.loose |= elements(root).any(|c| c.name == "body");
    }

    pub(super) fn fragment(&self) -> bool {
        !self.in_world && self.loose
    }
}

/// Whether the MJCF `text` (its root `<mujoco>` or `<mujocoinclude>`) is a
/// fragment: a `<mujocoinclude>`, or a `<mujoco>` whose bodies are not in a
/// `<worldbody>`.
pub(super) fn mjcf_fragment(text: &str, go_on: &mut GoOn<'_>) -> Result<bool, Streamed> {
    let mut include = false;
    let mut bodies = Bodies::default();
    stream(
        text,
        go_on,
        |tag| {
            include = tag.name == "mujocoinclude";
            Ok(!include)
        },
        |root| {
            bodies.add(&root);
            Ok(())
        },
    )?;
    Ok(include || bodies.fragment())
}

/// The error of a reading its [`GoOn`] stopped.
pub(super) fn stopped() -> DescriptionError {
    DescriptionError::new(
        ErrorKind::Stopped,
        "the reading was stopped by its caller".into(),
    )
}

/// `text` without a leading byte-order mark.
pub(super) fn without_bom(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}

/// Whether `text` could hold xacro markup at all: the xacro namespace, an
/// expression `${…}` or `$(…)`, an element `<xacro:…>`.
pub(super) fn might_be_xacro(text: &str) -> bool {
    ["${", "$(", XACRO_NS, "<xacro:"]
        .iter()
        .any(|m| text.contains(m))
}

/// Why a [`stream`] ended early.
pub(super) enum Streamed {
    /// The text is not XML (the message, to follow "cannot read … as a URDF: ").
    NotXml(String),
    /// The caller's [`GoOn`] said stop.
    Stopped,
    /// A callback refused.
    Described(DescriptionError),
}

impl From<DescriptionError> for Streamed {
    fn from(e: DescriptionError) -> Self {
        Streamed::Described(e)
    }
}

/// A copy of a start tag (RustyXML's is not `Clone`).
pub(super) fn copy_tag(t: &xml::StartTag) -> xml::StartTag {
    xml::StartTag {
        name: t.name.clone(),
        ns: t.ns.clone(),
        prefix: t.prefix.clone(),
        attributes: t.attributes.clone(),
    }
}

/// The end tag of `t`.
pub(super) fn end_of(t: &xml::StartTag) -> xml::EndTag {
    xml::EndTag {
        name: t.name.clone(),
        ns: t.ns.clone(),
        prefix: t.prefix.clone(),
    }
}

pub(super) fn builder_error(e: xml::BuilderError) -> Streamed {
    Streamed::NotXml(match e {
        xml::BuilderError::Parser(e) => format!(
            "it is not XML: line {}, column {}: {}",
            e.line, e.col, e.msg
        ),
        xml::BuilderError::ImproperNesting => {
            "it is not XML: its elements are not properly nested".into()
        }
        xml::BuilderError::NoElement => {
            "it is not XML: it ends before its root element is closed".into()
        }
    })
}

/// Read the XML `text` a piece at a time, each piece once: `root` gets the
/// root element's start tag and says whether to read on (false: the reading
/// ends there, `Ok`); then `batch` gets the root element holding the next
/// children of the root, whole, at most [`BATCH_ELEMENTS`] of them, until
/// the root closes (at least once). The text is given to the XML reader
/// [`CHUNK_BYTES`] at a time; `go_on` is asked after each chunk and each
/// batch. Elements nested more than [`MAX_DEPTH`] deep are refused as they
/// come; the text after the root element is not read (as RustyXML's own
/// reading of a document).
pub(super) fn stream(
    text: &str,
    go_on: &mut GoOn<'_>,
    mut root: impl FnMut(&xml::StartTag) -> Result<bool, DescriptionError>,
    mut batch: impl FnMut(xml::Element) -> Result<(), DescriptionError>,
) -> Result<(), Streamed> {
    let run = std::panic::AssertUnwindSafe(|| -> Result<(), Streamed> {
        let mut parser = xml::Parser::new();
        let mut at = 0;
        let mut depth = 0usize;
        // The root's start tag, and the builder of the batch being read.
        let mut open: Option<(xml::StartTag, xml::ElementBuilder)> = None;
        let mut children = 0usize;
        let start = |tag: &xml::StartTag| {
            let mut b = xml::ElementBuilder::new();
            b.handle_event(Ok(xml::Event::ElementStart(copy_tag(tag))));
            b
        };
        loop {
            if at < text.len() {
                let mut end = (at + CHUNK_BYTES).min(text.len());
                while !text.is_char_boundary(end) {
                    end += 1;
                }
                parser.feed_str(&text[at..end]);
                at = end;
            }
            for event in parser.by_ref() {
                let event = event.map_err(|e| builder_error(xml::BuilderError::Parser(e)))?;
                let closed = match &event {
                    xml::Event::ElementStart(tag) => {
                        depth += 1;
                        if depth > MAX_DEPTH {
                            return Err(Streamed::NotXml(format!(
                                "its elements nest more than {MAX_DEPTH} deep (a URDF nests 5)"
                            )));
                        }
                        if depth == 1 {
                            if !root(tag)? {
                                return Ok(());
                            }
                            open = Some((copy_tag(tag), start(tag)));
                            continue;
                        }
                        false
                    }
                    xml::Event::ElementEnd(_) => {
                        depth = depth
                            .checked_sub(1)
                            .ok_or_else(|| builder_error(xml::BuilderError::ImproperNesting))?;
                        true
                    }
                    _ => false,
                };
                let Some((tag, b)) = open.as_mut() else {
                    continue; // before the root: text, comments, declarations
                };
                match b.handle_event(Ok(event)) {
                    Some(Ok(element)) => {
                        // The root closed: the last batch.
                        batch(element)?;
                        return Ok(());
                    }
                    Some(Err(e)) => return Err(builder_error(e)),
                    None => {}
                }
                if closed && depth == 1 {
                    children += 1;
                    if children == BATCH_ELEMENTS {
                        children = 0;
                        let full = core::mem::replace(b, start(tag));
                        let mut full = full;
                        match full.handle_event(Ok(xml::Event::ElementEnd(end_of(tag)))) {
                            Some(Ok(element)) => batch(element)?,
                            Some(Err(e)) => return Err(builder_error(e)),
                            None => {}
                        }
                        if !go_on() {
                            return Err(Streamed::Stopped);
                        }
                    }
                }
            }
            if at == text.len() {
                return Err(builder_error(xml::BuilderError::NoElement));
            }
            if !go_on() {
                return Err(Streamed::Stopped);
            }
        }
    });
    std::panic::catch_unwind(run)
        .unwrap_or_else(|_| Err(Streamed::NotXml("the XML parser could not read it".into())))
}
