//! How a finished output is recognised, so that a job run again can skip work already
//! done: the output's [`OutputStamp`] (size and CRC-32 of its bytes) and the
//! [`fingerprint`] of everything besides the input that decides those bytes (the
//! options, the format, qem's version).
//!
//! `qem batch --resume` and the tile jobs ([`crate::tiles::jobs`]) record both when an
//! output is complete and compare them before they skip it: a record of a file cut
//! short, changed since, or made with other options does not count, and the work is
//! done again (to the same bytes, since every output is deterministic).

use serde::{Deserialize, Serialize};
use std::fs::File;
use std::io::Read;
use std::path::Path;

/// What a complete output is: its size and the CRC-32 of its bytes.
///
/// Serialised as `{"size": ..., "crc32": ...}` (the CRC-32 as a number).
///
/// ```
/// use qem_mesh::io::OutputStamp;
/// let stamp = OutputStamp::of_bytes(b"123456789");
/// assert_eq!(stamp.size(), 9);
/// assert_eq!(stamp.crc32(), 0xcbf4_3926); // the CRC-32 check value
/// ```
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq)]
pub struct OutputStamp {
    size: u64,
    crc32: u32,
}

impl OutputStamp {
    /// The stamp of a file holding `bytes`.
    pub fn of_bytes(bytes: &[u8]) -> OutputStamp {
        OutputStamp {
            size: bytes.len() as u64,
            crc32: crc32fast::hash(bytes),
        }
    }

    /// Reads `path` through to stamp it; `None` when it cannot be read.
    pub fn of(path: &Path) -> Option<OutputStamp> {
        let mut file = File::open(path).ok()?;
        let mut hasher = crc32fast::Hasher::new();
        let mut buf = vec![0u8; 1 << 16];
        let mut size = 0u64;
        loop {
            let n = file.read(&mut buf).ok()?;
            if n == 0 {
                break;
            }
            hasher.update(&buf[..n]);
            size += n as u64;
        }
        Some(OutputStamp {
            size,
            crc32: hasher.finalize(),
        })
    }

    /// The size in bytes.
    pub fn size(&self) -> u64 {
        self.size
    }

    /// The CRC-32 (IEEE) of the bytes.
    pub fn crc32(&self) -> u32 {
        self.crc32
    }
}

/// A fingerprint of everything that decides an output's bytes besides its input: the
/// options (their `Debug` form holds every field), the output format and qem's
/// version, as a CRC-32 in hex (8 digits).
///
/// A change of any of them gives another fingerprint (up to CRC-32 collisions), so a
/// record made with other options or by another version of qem is not taken for the
/// work asked now. The `Debug` form includes type and field names: renaming them
/// changes every fingerprint, as a new version would.
///
/// ```
/// use qem_mesh::io::fingerprint;
/// assert_eq!(fingerprint(&(1, 0.5), &"obj"), fingerprint(&(1, 0.5), &"obj"));
/// assert_ne!(fingerprint(&(1, 0.5), &"obj"), fingerprint(&(1, 0.25), &"obj"));
/// assert_eq!(fingerprint(&(1, 0.5), &"obj").len(), 8);
/// ```
pub fn fingerprint(options: &impl std::fmt::Debug, format: &impl std::fmt::Debug) -> String {
    let text = format!("{options:?}|{format:?}|qem {}", env!("CARGO_PKG_VERSION"));
    format!("{:08x}", crc32fast::hash(text.as_bytes()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fingerprint_changes_with_any_option() {
        assert_eq!(
            fingerprint(&(1, 0.5), &"obj"),
            fingerprint(&(1, 0.5), &"obj")
        );
        assert_ne!(
            fingerprint(&(1, 0.5), &"obj"),
            fingerprint(&(1, 0.25), &"obj")
        );
        assert_ne!(
            fingerprint(&(1, 0.5), &"obj"),
            fingerprint(&(1, 0.5), &"ply")
        );
    }

    #[test]
    fn a_file_is_stamped_as_its_bytes() {
        let dir = tempfile::tempdir().expect("a temporary directory");
        let path = dir.path().join("f");
        // Longer than the read buffer, so the stamp spans several reads.
        let bytes: Vec<u8> = (0..200_000u32).map(|i| (i * 7 % 251) as u8).collect();
        std::fs::write(&path, &bytes).expect("write");
        assert_eq!(OutputStamp::of(&path), Some(OutputStamp::of_bytes(&bytes)));
        assert_eq!(OutputStamp::of(&dir.path().join("missing")), None);
    }
}
