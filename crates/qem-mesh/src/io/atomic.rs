//! Atomic file writes, and the removal of the temporary files that killed writers leave.
//!
//! Every file qem writes goes first to a temporary file beside it, named
//! `.NAME.qem-tmp-PID-N` (the writer's process id and a per-process counter), which is
//! flushed to disk and renamed over `NAME`. A process killed between the two leaves the
//! temporary file behind; [`remove_stale_temporaries`] removes such files once their
//! writer is gone.

use std::fs::File;
use std::io::{ErrorKind, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime};

use super::IoError;

/// What qem's temporary file names hold between the target's name and the writer's
/// process id: `.NAME.qem-tmp-PID-N`.
pub const TEMP_MARKER: &str = ".qem-tmp-";

/// Where no process table can be asked (no `/proc`), a temporary file is taken as
/// stale only when it has not been modified for this long (a day): no write of qem's
/// takes that long, and a live writer's file is never removed.
pub const STALE_AGE_WITHOUT_PROC: Duration = Duration::from_secs(24 * 3600);

/// Writes `path` atomically: `write` fills a new temporary file in the same directory
/// (named `.NAME.qem-tmp-PID-N`, see [`TEMP_MARKER`]), which is flushed to disk and
/// renamed over `path`. On any error the temporary file is removed, so `path` either
/// keeps its old content or gets the complete new one; the error names `path` and, for
/// the usual causes (missing or read-only directory, full disk), says which it is.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use std::io::Write;
/// let dir = tempfile::tempdir()?;
/// let path = dir.path().join("notes.txt");
/// qem_mesh::io::write_atomically(&path, |f| f.write_all(b"complete\n"))?;
/// assert_eq!(std::fs::read(&path)?, b"complete\n");
///
/// let missing = dir.path().join("no/such/dir/notes.txt");
/// let err = qem_mesh::io::write_atomically(&missing, |f| f.write_all(b"x")).unwrap_err();
/// assert!(err.to_string().contains("cannot write (its directory does not exist)"));
/// # Ok(()) }
/// ```
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut File) -> std::io::Result<()>,
) -> Result<(), IoError> {
    write_then(path, write, |tmp| std::fs::rename(tmp, path)).map(|_| ())
}

/// `value` as pretty-printed JSON (two-space indents, fields in declaration order) and
/// a final newline, written to `path` atomically ([`write_atomically`]). Every JSON
/// file qem writes (reports, the tile jobs' manifest and statuses) goes through here, so
/// they share one layout.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// let path = dir.path().join("counts.json");
/// qem_mesh::io::write_json_atomically(&path, &[1, 2])?;
/// assert_eq!(std::fs::read_to_string(&path)?, "[\n  1,\n  2\n]\n");
/// # Ok(()) }
/// ```
pub fn write_json_atomically(path: &Path, value: &impl serde::Serialize) -> Result<(), IoError> {
    write_atomically(path, |file| {
        let mut out = std::io::BufWriter::new(file);
        serde_json::to_writer_pretty(&mut out, value)?;
        out.write_all(b"\n")?;
        out.flush()
    })
}

/// [`write_atomically`], but never over a file that is there: the complete file is
/// published under `path` only if nothing has that name (a link, not a rename, so that
/// a writer racing for the name cannot be overwritten either). `Ok(false)` when
/// something had the name; the temporary file is removed either way.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use std::io::Write;
/// let dir = tempfile::tempdir()?;
/// let path = dir.path().join("texture.png");
/// assert!(qem_mesh::io::write_new_atomically(&path, |f| f.write_all(b"first"))?);
/// assert!(!qem_mesh::io::write_new_atomically(&path, |f| f.write_all(b"second"))?);
/// assert_eq!(std::fs::read(&path)?, b"first");
/// # Ok(()) }
/// ```
pub fn write_new_atomically(
    path: &Path,
    write: impl FnOnce(&mut File) -> std::io::Result<()>,
) -> Result<bool, IoError> {
    write_then(path, write, |tmp| {
        let published = match std::fs::hard_link(tmp, path) {
            Ok(()) => Ok(true),
            Err(e) if e.kind() == ErrorKind::AlreadyExists => Ok(false),
            // A file system without links: checked, then renamed (a race with
            // another writer of the same name is possible there, and only there).
            Err(_) if std::fs::symlink_metadata(path).is_ok() => Ok(false),
            Err(_) => return std::fs::rename(tmp, path).map(|()| true),
        };
        std::fs::remove_file(tmp)?;
        published
    })
}

/// Writes a temporary file beside `path` with `write`, flushes it, and hands it to
/// `publish`; removes it when any step fails.
fn write_then<T>(
    path: &Path,
    write: impl FnOnce(&mut File) -> std::io::Result<()>,
    publish: impl FnOnce(&Path) -> std::io::Result<T>,
) -> Result<T, IoError> {
    let fail = |source: std::io::Error| IoError::File {
        path: path.to_path_buf(),
        action: write_action(source.kind()),
        source,
    };
    let (tmp, mut file) = create_temp_beside(path).map_err(fail)?;
    let result = write(&mut file)
        .and_then(|()| file.sync_all())
        .and_then(|()| {
            drop(file);
            publish(&tmp)
        })
        .map_err(fail);
    if result.is_err() {
        // Best effort: the error being reported is the one that matters.
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// The action of an [`IoError::File`] for a failed write, naming the usual causes in
/// words (the operating system's message follows it).
fn write_action(kind: ErrorKind) -> &'static str {
    match kind {
        ErrorKind::NotFound => "write (its directory does not exist)",
        ErrorKind::NotADirectory => "write (a part of its directory is a file)",
        ErrorKind::PermissionDenied => "write (its directory is not writable)",
        ErrorKind::ReadOnlyFilesystem => "write (the file system is read-only)",
        ErrorKind::StorageFull | ErrorKind::QuotaExceeded => {
            "write (the disk is full; nothing was left behind)"
        }
        _ => "write",
    }
}

/// Creates a fresh file next to `path` named `.NAME.qem-tmp-PID-N`.
fn create_temp_beside(path: &Path) -> std::io::Result<(PathBuf, File)> {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let dir = directory_of(path);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    loop {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let tmp = dir.join(format!(".{name}{TEMP_MARKER}{}-{n}", std::process::id()));
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
        {
            Ok(f) => return Ok((tmp, f)),
            Err(e) if e.kind() == ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
}

/// The directory a file path is in (`.` for a bare name).
///
/// ```
/// use std::path::Path;
/// assert_eq!(qem_mesh::io::directory_of(Path::new("out/a.obj")), Path::new("out"));
/// assert_eq!(qem_mesh::io::directory_of(Path::new("a.obj")), Path::new("."));
/// ```
pub fn directory_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// The writer's process id, when `name` is one of qem's temporary file names
/// (`.NAME.qem-tmp-PID-N`, PID and N decimal).
///
/// ```
/// use qem_mesh::io::temporary_owner;
/// assert_eq!(temporary_owner(".a.obj.qem-tmp-4242-7"), Some(4242));
/// assert_eq!(temporary_owner("a.obj.qem-tmp-4242-7"), None); // not hidden
/// assert_eq!(temporary_owner(".a.obj.qem-tmp-42x-7"), None);
/// assert_eq!(temporary_owner(".a.obj.tmp123"), None);
/// ```
pub fn temporary_owner(name: &str) -> Option<u32> {
    temporary_parts(name).map(|(_, pid)| pid)
}

/// The name of the file a temporary file of qem's is for, and its writer's process id
/// (`.NAME.qem-tmp-PID-N` gives `NAME` and `PID`).
fn temporary_parts(name: &str) -> Option<(&str, u32)> {
    let body = name.strip_prefix('.')?;
    // The last marker: NAME itself may contain one.
    let at = body.rfind(TEMP_MARKER)?;
    let (pid, n) = body[at + TEMP_MARKER.len()..].split_once('-')?;
    let decimal = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    if at == 0 || !decimal(pid) || !decimal(n) {
        return None;
    }
    Some((&body[..at], pid.parse().ok()?))
}

/// Whether process `pid` may still be writing: this process, or a process that
/// `/proc` lists. Without `/proc` (not Linux, or not mounted) nobody can say, and the
/// caller falls back on the file's age.
fn owner_state(pid: u32) -> Owner {
    if pid == std::process::id() {
        return Owner::Alive;
    }
    if !Path::new("/proc/self").exists() {
        return Owner::Unknown;
    }
    if Path::new("/proc").join(pid.to_string()).exists() {
        Owner::Alive
    } else {
        Owner::Gone
    }
}

enum Owner {
    Alive,
    Gone,
    Unknown,
}

/// Removes the temporary files of killed qem writers from `dir` (not recursively):
/// regular files whose names match qem's pattern ([`temporary_owner`]) and whose
/// writer is no longer running. Nothing else is touched.
///
/// Whether the writer runs is asked of `/proc` (Linux). A file whose writer is listed
/// there, or is this process, is kept; so is every file on a system without `/proc`
/// unless it has not changed for [`STALE_AGE_WITHOUT_PROC`]. (A writer in another PID
/// namespace sharing the directory, such as another container, is not listed in this
/// one's `/proc`: its write would then fail with an error, never leave a partial file.)
///
/// Returns the files removed, sorted. A directory that does not exist has none; other
/// errors of listing the directory are returned, errors of removing one file skip it.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// // PIDs on Linux stay below 2^22, so no process 99999999 exists.
/// std::fs::write(dir.path().join(".a.obj.qem-tmp-99999999-0"), b"half a mesh")?;
/// std::fs::write(dir.path().join("a.obj"), b"a mesh")?;
/// let removed = qem_mesh::io::remove_stale_temporaries(dir.path())?;
/// # #[cfg(target_os = "linux")]
/// assert_eq!(removed, vec![dir.path().join(".a.obj.qem-tmp-99999999-0")]);
/// assert!(dir.path().join("a.obj").exists());
/// # Ok(()) }
/// ```
pub fn remove_stale_temporaries(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    remove_stale_where(dir, |_| true)
}

/// [`remove_stale_temporaries`] for the temporary files of writers of `names` only
/// (file names in `dir`): for a job that writes only those files and shares the
/// directory with jobs on other machines, whose writers no process table here lists.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// std::fs::write(dir.path().join(".a.ply.qem-tmp-99999999-0"), b"half of a")?;
/// std::fs::write(dir.path().join(".b.ply.qem-tmp-99999999-0"), b"half of b")?;
/// let removed = qem_mesh::io::remove_stale_temporaries_of(dir.path(), &["a.ply"])?;
/// # #[cfg(target_os = "linux")]
/// assert_eq!(removed, vec![dir.path().join(".a.ply.qem-tmp-99999999-0")]);
/// assert!(dir.path().join(".b.ply.qem-tmp-99999999-0").exists());
/// # Ok(()) }
/// ```
pub fn remove_stale_temporaries_of(dir: &Path, names: &[&str]) -> std::io::Result<Vec<PathBuf>> {
    remove_stale_where(dir, |target| names.contains(&target))
}

/// Removes the stale temporary files of `dir` whose target name passes `wanted`.
fn remove_stale_where(dir: &Path, wanted: impl Fn(&str) -> bool) -> std::io::Result<Vec<PathBuf>> {
    let entries = match std::fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(e),
    };
    let mut removed = Vec::new();
    for entry in entries {
        let entry = entry?;
        let name = entry.file_name();
        let Some((target, pid)) = name.to_str().and_then(temporary_parts) else {
            continue;
        };
        if !wanted(target) {
            continue;
        }
        // Never follow a link or touch a directory that happens to match the name.
        let Ok(meta) = std::fs::symlink_metadata(entry.path()) else {
            continue;
        };
        if !meta.is_file() {
            continue;
        }
        let stale = match owner_state(pid) {
            Owner::Alive => false,
            Owner::Gone => true,
            Owner::Unknown => meta
                .modified()
                .ok()
                .and_then(|m| SystemTime::now().duration_since(m).ok())
                .is_some_and(|age| age >= STALE_AGE_WITHOUT_PROC),
        };
        if stale && std::fs::remove_file(entry.path()).is_ok() {
            removed.push(entry.path());
        }
    }
    removed.sort();
    Ok(removed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    /// A full disk shows as an error while writing or flushing; whichever step fails,
    /// the temporary file is removed and the target keeps its old content.
    #[test]
    fn a_full_disk_leaves_the_old_file_and_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("mesh.obj");
        std::fs::write(&path, b"old").unwrap();
        let err = write_atomically(&path, |f| {
            f.write_all(b"half of the new")?;
            Err(std::io::Error::new(
                ErrorKind::StorageFull,
                "No space left on device",
            ))
        })
        .unwrap_err();
        assert_eq!(
            err.to_string(),
            format!(
                "{}: cannot write (the disk is full; nothing was left behind): \
                 No space left on device",
                path.display()
            )
        );
        assert_eq!(names(dir.path()), vec!["mesh.obj"]);
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
    }

    /// What the operating system says when a disk is full: writing to `/dev/full`
    /// fails with `StorageFull`, the kind `write_action` names.
    #[cfg(target_os = "linux")]
    #[test]
    fn dev_full_reports_storage_full() {
        let Ok(mut f) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
            eprintln!("SKIPPED: no /dev/full");
            return;
        };
        let e = f.write_all(&[0u8; 1 << 16]).and_then(|()| f.flush());
        let e = e.unwrap_err();
        assert_eq!(e.kind(), ErrorKind::StorageFull);
        assert_eq!(
            write_action(e.kind()),
            "write (the disk is full; nothing was left behind)"
        );
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn only_stale_files_of_the_pattern_are_removed() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let own = std::process::id();
        let mut child = std::process::Command::new("sleep")
            .arg("30")
            .spawn()
            .unwrap();
        let live = child.id();
        let files = [
            ".a.obj.qem-tmp-99999999-0".to_string(), // dead writer: removed
            ".b.ply.qem-tmp-99999998-12".to_string(), // dead writer: removed
            format!(".c.obj.qem-tmp-{own}-0"),       // this process: kept
            format!(".d.obj.qem-tmp-{live}-3"),      // a live process: kept
            "e.obj.qem-tmp-99999999-0".to_string(),  // not hidden: not ours
            ".f.obj.qem-tmp-99999999-x".to_string(), // no counter: not ours
            ".g.obj.tmpA1b2C3".to_string(),          // another program's
            "h.obj".to_string(),
        ];
        for f in &files {
            std::fs::write(d.join(f), b"x").unwrap();
        }
        // A directory with a matching name is never removed.
        std::fs::create_dir(d.join(".i.obj.qem-tmp-99999999-1")).unwrap();
        let removed = remove_stale_temporaries(d).unwrap();
        let _ = child.kill();
        let _ = child.wait();
        assert_eq!(removed, vec![d.join(&files[0]), d.join(&files[1])]);
        let mut left: Vec<String> = files[2..].to_vec();
        left.push(".i.obj.qem-tmp-99999999-1".to_string());
        left.sort();
        assert_eq!(names(d), left);
        assert!(remove_stale_temporaries(&d.join("missing"))
            .unwrap()
            .is_empty());
    }
}
