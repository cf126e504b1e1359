//! [`IoError`]: every way loading or saving can fail. Its `Display` always starts with the path
//! (or the name given to `load_from_bytes`), then the place in the file ([`Location`]: a line for
//! text formats, a byte offset or an element for binary ones) and what is wrong there.

use std::fmt;
use std::path::{Path, PathBuf};

/// Where in a file a problem is.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Location {
    /// 1-based line number (text formats).
    Line(usize),
    /// 0-based byte offset (binary formats).
    Byte(u64),
    /// A named element, e.g. "mesh 0, primitive 1" or "accessor 3".
    Element(String),
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(line) => write!(f, "line {line}"),
            Location::Byte(offset) => write!(f, "byte {offset}"),
            Location::Element(element) => f.write_str(element),
        }
    }
}

#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum IoError {
    /// The file could not be opened or read.
    #[error("{}: cannot read the file: {source}", path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    /// Writing failed; nothing was left behind and an existing file is unchanged.
    #[error("{}: cannot write the file: {source}", path.display())]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The extension names no supported format.
    #[error(
        "{}: unknown file extension {extension:?}: supported are obj, gltf, glb, ply, stl, off",
        path.display()
    )]
    UnknownFormat { path: PathBuf, extension: String },
    /// Bad data at a known place in the file.
    #[error("{}: {at}: {message}", path.display())]
    Parse {
        path: PathBuf,
        at: Location,
        message: String,
    },
    /// A problem with the file as a whole (empty, no triangles, unsupported variant).
    #[error("{}: {message}", path.display())]
    Invalid { path: PathBuf, message: String },
    /// The mesh cannot be written (non-finite positions, indices out of range, no triangles);
    /// nothing was written.
    #[error("{}: refusing to write: {message}; nothing was written", path.display())]
    Refused { path: PathBuf, message: String },
}

impl IoError {
    pub(crate) fn invalid(path: &Path, message: impl Into<String>) -> IoError {
        IoError::Invalid {
            path: path.to_owned(),
            message: message.into(),
        }
    }

    pub(crate) fn at_line(path: &Path, line: usize, message: impl Into<String>) -> IoError {
        IoError::Parse {
            path: path.to_owned(),
            at: Location::Line(line),
            message: message.into(),
        }
    }

    pub(crate) fn at_byte(path: &Path, offset: usize, message: impl Into<String>) -> IoError {
        IoError::Parse {
            path: path.to_owned(),
            at: Location::Byte(offset as u64),
            message: message.into(),
        }
    }

    pub(crate) fn at_element(
        path: &Path,
        element: impl Into<String>,
        message: impl Into<String>,
    ) -> IoError {
        IoError::Parse {
            path: path.to_owned(),
            at: Location::Element(element.into()),
            message: message.into(),
        }
    }

    /// The path (or name) the error is about.
    pub fn path(&self) -> &Path {
        match self {
            IoError::Read { path, .. }
            | IoError::Write { path, .. }
            | IoError::UnknownFormat { path, .. }
            | IoError::Parse { path, .. }
            | IoError::Invalid { path, .. }
            | IoError::Refused { path, .. } => path,
        }
    }
}
