//! Error types of the readers and writers.

use std::fmt;
use std::path::PathBuf;

use super::Format;
use crate::InputError;

/// Where in a file a [`ReadError`] was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Location {
    /// A 1-based line number, for text formats and text headers.
    Line(usize),
    /// A 0-based byte offset into the (decompressed) data, for binary formats.
    Byte(u64),
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(n) => write!(f, "line {n}"),
            Location::Byte(n) => write!(f, "byte {n}"),
        }
    }
}

/// What went wrong while reading mesh data. See [`ReadError`] for the where.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum ReadErrorKind {
    /// The file name's extension is not one qem reads or writes.
    UnsupportedExtension {
        /// The extension as found (without the dot), or empty when there is none.
        extension: String,
    },
    /// The data is empty.
    Empty,
    /// The data is not in the format its name claims.
    NotThisFormat {
        /// The format the name (or the caller) claims.
        claimed: Format,
        /// What the data looks like instead, when recognisable, e.g. `"a PNG image"`.
        looks_like: Option<&'static str>,
        /// Why it was refused.
        detail: String,
    },
    /// The data ends before what its header or syntax promises.
    Truncated {
        /// What was expected, e.g. `"after 12 of 5000 vertices"`.
        detail: String,
    },
    /// The data breaks the format's syntax or rules.
    Malformed {
        /// What is wrong, e.g. `"vertex 17: expected 3 coordinates, found 2"`.
        detail: String,
    },
    /// A count in the data is above the limit qem accepts ([`crate::MAX_ELEMENTS`]).
    TooLarge {
        /// What is counted, e.g. `"vertices"`.
        what: String,
        /// The claimed count.
        count: u64,
        /// The limit.
        limit: u64,
    },
    /// The data parsed but does not form a usable mesh (no triangles, non-finite
    /// coordinate, index out of range).
    Mesh(InputError),
    /// An external buffer file of a `.gltf` could not be read.
    BufferFile {
        /// The buffer's index in the glTF's `buffers`.
        buffer: usize,
        /// The file as the glTF names it, percent escapes decoded (`data%20file.bin` is
        /// `data file.bin`), relative to the `.gltf` file's directory.
        uri: String,
        /// The operating system's error.
        detail: String,
    },
    /// The gzip layer is corrupt or decompresses to more than the limit.
    Gzip {
        /// What went wrong.
        detail: String,
    },
}

/// Why mesh data could not be read: a cause and, when known, a place.
///
/// Its `Display` is one line, e.g.
/// `line 12: vertex 3: expected 3 coordinates, found 2`.
#[derive(Clone, Debug, PartialEq)]
pub struct ReadError {
    kind: ReadErrorKind,
    location: Option<Location>,
}

impl ReadError {
    /// Makes an error from a cause and an optional place.
    pub fn new(kind: ReadErrorKind, location: Option<Location>) -> Self {
        Self { kind, location }
    }

    /// The cause.
    pub fn kind(&self) -> &ReadErrorKind {
        &self.kind
    }

    /// The place, when known.
    pub fn location(&self) -> Option<Location> {
        self.location
    }

    pub(crate) fn malformed(at: Location, detail: impl Into<String>) -> Self {
        Self::new(
            ReadErrorKind::Malformed {
                detail: detail.into(),
            },
            Some(at),
        )
    }

    pub(crate) fn truncated(at: Location, detail: impl Into<String>) -> Self {
        Self::new(
            ReadErrorKind::Truncated {
                detail: detail.into(),
            },
            Some(at),
        )
    }

    pub(crate) fn too_large(at: Location, what: impl Into<String>, count: u64) -> Self {
        Self::new(
            ReadErrorKind::TooLarge {
                what: what.into(),
                count,
                limit: crate::MAX_ELEMENTS as u64,
            },
            Some(at),
        )
    }

    pub(crate) fn mesh(at: Option<Location>, e: InputError) -> Self {
        Self::new(ReadErrorKind::Mesh(e), at)
    }

    pub(crate) fn not_this_format(
        claimed: Format,
        looks_like: Option<&'static str>,
        detail: impl Into<String>,
    ) -> Self {
        Self::new(
            ReadErrorKind::NotThisFormat {
                claimed,
                looks_like,
                detail: detail.into(),
            },
            None,
        )
    }
}

impl fmt::Display for ReadErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ReadErrorKind::UnsupportedExtension { extension } => {
                if extension.is_empty() {
                    write!(f, "the file name has no extension")?;
                } else {
                    write!(f, "unsupported file extension \".{extension}\"")?;
                }
                write!(f, "; supported: {}", super::SUPPORTED_EXTENSIONS)
            }
            ReadErrorKind::Empty => write!(f, "the file is empty"),
            ReadErrorKind::NotThisFormat {
                claimed,
                looks_like,
                detail,
            } => {
                write!(f, "not {} file: {detail}", claimed.article_name())?;
                if let Some(other) = looks_like {
                    write!(f, " (it looks like {other})")?;
                }
                Ok(())
            }
            ReadErrorKind::Truncated { detail } => write!(f, "unexpected end of file {detail}"),
            ReadErrorKind::Malformed { detail } => write!(f, "{detail}"),
            ReadErrorKind::TooLarge { what, count, limit } => {
                write!(f, "{what} {count}, more than the limit of {limit}")
            }
            ReadErrorKind::Mesh(e) => write!(f, "{e}"),
            ReadErrorKind::Gzip { detail } => write!(f, "gzip: {detail}"),
            ReadErrorKind::BufferFile {
                buffer,
                uri,
                detail,
            } => {
                write!(f, "buffer {buffer}: cannot read its file {uri:?}: {detail}")
            }
        }
    }
}

impl fmt::Display for ReadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(at) = self.location {
            write!(f, "{at}: ")?;
        }
        write!(f, "{}", self.kind)
    }
}

impl std::error::Error for ReadError {}

/// Why reading or writing a file failed. Its `Display` is one line that starts with
/// the path.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum IoError {
    /// The file was read but its content was refused.
    #[error("{}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// What was wrong with its content.
        source: ReadError,
    },
    /// The operating system refused an operation on the file.
    #[error("{}: cannot {action}: {source}", path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// What was attempted: `"read"`, `"write"`, ...
        action: &'static str,
        /// The operating system's error.
        source: std::io::Error,
    },
}
