//! The manifest of `qem batch`: which inputs are done, so that `--resume` skips them.
//!
//! It lives beside the outputs, in `OUT_DIR/.qem-batch-manifest.jsonl`: JSON Lines, a
//! header line and then one record per completed input, appended (and flushed to disk)
//! as soon as its output has been renamed into place. Appending keeps the cost of a
//! record the same at the 10th file and at the 10,000th (rewriting the whole manifest
//! after each file would cost quadratic time and disk writes over a long batch). A run
//! killed in the middle of an append leaves at most one torn last line, which does not
//! parse and is dropped; at its start every run rewrites the manifest atomically
//! (temporary file and rename) with only the records it keeps, so the torn line never
//! reaches the next append.
//!
//! A record counts for `--resume` only when everything it names still holds: the same
//! input path, size and modification time, the same output path, an output file of
//! the recorded size and CRC-32, and the same options and qem version (a fingerprint;
//! the stamp and the fingerprint are `qem_mesh::io`'s, which the tile jobs use too).
//! Anything else (a record lost, a changed input, a touched output) means the input
//! is simply run again; since every output is written atomically and deterministically,
//! running it again gives the same bytes.

pub use qem_mesh::io::{fingerprint, OutputStamp};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The manifest's file name inside the output directory.
pub const MANIFEST_NAME: &str = ".qem-batch-manifest.jsonl";

/// The header's version; a manifest of another version is started afresh.
const VERSION: u32 = 1;

#[derive(Serialize, Deserialize)]
struct Header {
    qem_batch_manifest: u32,
}

/// How an input file is recognised as unchanged: size and modification time, the test
/// `make` and `rsync` use (a content hash would read every input again on each resume).
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq)]
pub struct InputStamp {
    size: u64,
    mtime_s: u64,
    mtime_ns: u32,
}

impl InputStamp {
    /// The stamp of `path` now, `None` when its metadata cannot be read.
    pub fn of(path: &Path) -> Option<InputStamp> {
        let meta = std::fs::metadata(path).ok()?;
        let since = meta
            .modified()
            .ok()?
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap_or_default();
        Some(InputStamp {
            size: meta.len(),
            mtime_s: since.as_secs(),
            mtime_ns: since.subsec_nanos(),
        })
    }
}

/// One completed input.
#[derive(Serialize, Deserialize, Clone, Debug)]
pub struct Record {
    /// The input, as the report names it.
    pub input: String,
    input_stamp: InputStamp,
    /// The output written for it.
    pub output: String,
    output_stamp: OutputStamp,
    /// The fingerprint of the options and version that wrote the output.
    options: String,
    /// The `qem simplify` report of the run that wrote it.
    pub report: serde_json::Value,
}

impl Record {
    /// A record of `input` (with its stamp taken before it was read) written to
    /// `output` under `options` (a [`fingerprint`]); the output is stamped now.
    pub fn new(
        input: String,
        input_stamp: InputStamp,
        output: &Path,
        options: &str,
        report: serde_json::Value,
    ) -> Option<Record> {
        Some(Record {
            input,
            input_stamp,
            output: output.display().to_string(),
            output_stamp: OutputStamp::of(output)?,
            options: options.to_string(),
            report,
        })
    }
}

/// The manifest of one run: the records kept from earlier runs and the open file
/// new records are appended to.
pub struct Manifest {
    path: PathBuf,
    earlier: BTreeMap<String, Record>,
    file: Mutex<File>,
}

impl Manifest {
    /// Opens the manifest of `out_dir`. With `resume`, the records of earlier runs are
    /// kept (the last one of each input; torn or unreadable lines are dropped);
    /// without, the manifest starts empty. Either way it is rewritten atomically first,
    /// so a read-only or full output directory is found here, before any work.
    pub fn open(out_dir: &Path, resume: bool) -> Result<Manifest, String> {
        let path = out_dir.join(MANIFEST_NAME);
        let earlier = if resume {
            read_records(&path)
        } else {
            BTreeMap::new()
        };
        qem_mesh::io::write_atomically(&path, |f| {
            let mut out = std::io::BufWriter::new(f);
            serde_json::to_writer(
                &mut out,
                &Header {
                    qem_batch_manifest: VERSION,
                },
            )?;
            out.write_all(b"\n")?;
            for record in earlier.values() {
                serde_json::to_writer(&mut out, record)?;
                out.write_all(b"\n")?;
            }
            out.flush()
        })
        .map_err(|e| format!("{e}; nothing was simplified"))?;
        let file = std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .map_err(|e| format!("{}: cannot open for appending: {e}", path.display()))?;
        Ok(Manifest {
            path,
            earlier,
            file: Mutex::new(file),
        })
    }

    /// The earlier record of `input`, if it still holds: same input stamp, output path
    /// and options, and an output on disk of the recorded size and CRC-32.
    pub fn completed(
        &self,
        input: &str,
        stamp: Option<InputStamp>,
        output: &Path,
        options: &str,
    ) -> Option<&Record> {
        let record = self.earlier.get(input)?;
        let holds = stamp == Some(record.input_stamp)
            && record.output == output.display().to_string()
            && record.options == options
            && OutputStamp::of(output) == Some(record.output_stamp);
        holds.then_some(record)
    }

    /// Appends `record` as one line and flushes it to disk.
    pub fn append(&self, record: &Record) -> Result<(), String> {
        let fail = |e: &dyn std::fmt::Display| {
            format!(
                "{}: cannot record a completed file: {e}; --resume will run it again",
                self.path.display()
            )
        };
        let mut line = serde_json::to_vec(record).map_err(|e| fail(&e))?;
        line.push(b'\n');
        // One write of the whole line: a kill leaves it whole or torn at the end, and
        // a torn last line is dropped when the manifest is read.
        let file = self.file.lock().unwrap_or_else(|p| p.into_inner());
        (&*file)
            .write_all(&line)
            .and_then(|()| file.sync_data())
            .map_err(|e| fail(&e))
    }
}

/// The records of a manifest file, the last one of each input; nothing when the file
/// is missing, of another version, or unreadable.
fn read_records(path: &Path) -> BTreeMap<String, Record> {
    let mut records = BTreeMap::new();
    let Ok(file) = File::open(path) else {
        return records;
    };
    let mut lines = std::io::BufReader::new(file).split(b'\n');
    let header = lines
        .next()
        .and_then(Result::ok)
        .and_then(|l| serde_json::from_slice::<Header>(&l).ok());
    if header.map(|h| h.qem_batch_manifest) != Some(VERSION) {
        return records;
    }
    for line in lines {
        let Ok(line) = line else { break };
        if let Ok(record) = serde_json::from_slice::<Record>(&line) {
            records.insert(record.input.clone(), record);
        }
    }
    records
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(dir: &Path, input: &str, output: &str, body: &[u8]) -> Record {
        let out = dir.join(output);
        std::fs::write(&out, body).unwrap();
        let stamp = InputStamp {
            size: 1,
            mtime_s: 2,
            mtime_ns: 3,
        };
        Record::new(
            input.into(),
            stamp,
            &out,
            "opts",
            serde_json::json!({"k": 1}),
        )
        .unwrap()
    }

    #[test]
    fn records_survive_a_torn_last_line_and_a_rerun() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let m = Manifest::open(d, true).unwrap();
        let a = record(d, "in/a.obj", "a.obj", b"mesh a");
        let b = record(d, "in/b.obj", "b.obj", b"mesh b");
        m.append(&a).unwrap();
        m.append(&b).unwrap();
        drop(m);
        // A kill in the middle of a third append.
        let mut f = std::fs::OpenOptions::new()
            .append(true)
            .open(d.join(MANIFEST_NAME))
            .unwrap();
        f.write_all(b"{\"input\":\"in/c.obj\",\"inp").unwrap();
        drop(f);

        let m = Manifest::open(d, true).unwrap();
        let stamp = Some(a.input_stamp);
        assert!(m
            .completed("in/a.obj", stamp, &d.join("a.obj"), "opts")
            .is_some());
        assert!(m
            .completed("in/b.obj", stamp, &d.join("b.obj"), "opts")
            .is_some());
        assert!(m
            .completed("in/c.obj", stamp, &d.join("c.obj"), "opts")
            .is_none());
        // Other options, another input stamp, another output path: not complete.
        assert!(m
            .completed("in/a.obj", stamp, &d.join("a.obj"), "other")
            .is_none());
        let newer = Some(InputStamp {
            mtime_ns: 4,
            ..a.input_stamp
        });
        assert!(m
            .completed("in/a.obj", newer, &d.join("a.obj"), "opts")
            .is_none());
        assert!(m
            .completed("in/a.obj", stamp, &d.join("b.obj"), "opts")
            .is_none());
        // An output changed after it was recorded, even at the same size.
        std::fs::write(d.join("b.obj"), b"mesh B").unwrap();
        assert!(m
            .completed("in/b.obj", stamp, &d.join("b.obj"), "opts")
            .is_none());
        // The rewrite at open dropped the torn line: the file is whole lines only.
        let text = std::fs::read_to_string(d.join(MANIFEST_NAME)).unwrap();
        assert_eq!(text.lines().count(), 3, "{text}");
        assert!(text.ends_with('\n'));
        drop(m);
        // Without --resume the manifest starts empty.
        let m = Manifest::open(d, false).unwrap();
        assert!(m
            .completed("in/a.obj", stamp, &d.join("a.obj"), "opts")
            .is_none());
    }
}
