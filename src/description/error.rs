//! Why a description could not be read or reduced: a message that names the
//! file, the element and what to do, and a kind a front can map (Python:
//! `FileNotFoundError` for a missing file, `ConfigError` otherwise; C: a
//! status).

use alloc::string::String;
use core::fmt;

/// What went wrong, by kind.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The file could not be read (missing, unreadable, not UTF-8).
    Io,
    /// The text is not a URDF the parser reads (not XML, a missing
    /// attribute, a number that is not one).
    Parse,
    /// The text is xacro (macros that must be expanded first).
    Xacro,
    /// The tree is not one: a missing link, a link with two parents, a loop,
    /// two elements of one name.
    Structure,
    /// A number out of its range (not finite, a negative mass, lower > upper).
    Value,
    /// The reduction to an arm: an unknown `tip` or `fix` name, no joint to
    /// drive, chains that tie, a joint an arm cannot have on its path.
    Arm,
    /// The reading was stopped by its caller (a front's Ctrl-C).
    Stopped,
}

/// A description that could not be read or reduced (SPEC §21).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DescriptionError {
    kind: ErrorKind,
    message: String,
}

impl DescriptionError {
    /// An error of `kind` with its whole `message`.
    pub fn new(kind: ErrorKind, message: String) -> Self {
        Self { kind, message }
    }

    /// What went wrong, by kind.
    pub fn kind(&self) -> ErrorKind {
        self.kind
    }

    /// The message: the file, the element and what to do.
    pub fn message(&self) -> &str {
        &self.message
    }
}

impl fmt::Display for DescriptionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl core::error::Error for DescriptionError {}
