//! The split from a stream of triangles (a file read by
//! [`stream_path`](crate::io::stream_path), or a mesh in memory): the triangles go to
//! disk as they come, and the tiles are built from there one at a time, so the split
//! never holds every triangle.
//!
//! 1. **Spill**: each triangle's corners (72 bytes) are appended to a file, its
//!    centroid offered to the cut's [`Sample`].
//! 2. **Cut** ([`Cut`]), then **route**: the spill is read back in order and each
//!    triangle appended to its tile's file (the spill is then removed).
//! 3. **Borders**: each tile's distinct corner positions (their bits, `-0.0` as
//!    `+0.0`), sorted, go to a file of its own; one merge of those files finds the
//!    positions more than one tile uses, and gives each tile its own sorted list of
//!    them.
//! 4. **Tiles**: each tile's triangles are read back, numbered by [`TileBuilder`] (a
//!    border vertex is one at a border position) and handed to the caller.
//!
//! It gives the tiles [`Tiling`](super::Tiling) gives for the same triangles (the same
//! cut, the same numbering), without the mesh; but for zero coordinates, whose sign
//! a tile file keeps as its first corner there has it, where `Tiling` keeps the
//! welded vertex's. What it holds: the sample (at most
//! [`SAMPLE_CAP`](super::SAMPLE_CAP) centroids, 32 bytes each) and a buffer per tile
//! while the triangles come; then one tile at a time (its positions' bits to sort, 72
//! bytes a triangle; then the tile being numbered). On disk, in a temporary directory
//! inside the tile directory (removed at the end, or by the next split if the process
//! was killed): 72 bytes a triangle twice over while routing, then once.
//!
//! Files open at once: one per tile while routing, two per tile while the borders are
//! found. The process's soft limit on open files is raised towards its hard limit
//! when the split needs more (the `rlimit` crate); a split that would still need more
//! than the system allows is refused before it writes a tile file, saying how many
//! (often 1,024 by default, so about 480 tiles, before raising).

use super::{centroid, position_key, Cut, Sample, Tile, TileBuilder};
use crate::io::{IoError, TriangleSink};
use std::collections::BinaryHeap;
use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

/// The prefix of the split's temporary directory inside the tile directory.
pub(super) const SCRATCH_PREFIX: &str = ".qem-split-";

/// Bytes of one triangle on disk: nine little-endian `f64`.
const TRIANGLE_BYTES: usize = 72;

/// Bytes of one position's bits on disk: three little-endian `u64`.
const KEY_BYTES: usize = 24;

/// Buffer of each file written or read, at most (a split may have many tiles open at
/// once while routing).
const BUFFER_BYTES: usize = 1 << 16;

/// What the triangles streamed into a [`Spill`] came to.
pub(super) struct Spilled {
    dir: tempfile::TempDir,
    pub(super) triangles: u64,
    /// The box of every corner; empty (min > max) without triangles.
    pub(super) bbox: Box3,
    sample: Sample,
    spill: PathBuf,
}

/// The spill's sink: each triangle to the spill file, its centroid to the sample.
pub(super) struct Spill {
    /// (Before `dir`: fields drop in order, and a directory with an open file in it
    /// cannot be removed everywhere.)
    out: BufWriter<File>,
    dir: tempfile::TempDir,
    path: PathBuf,
    sample: Sample,
    count: u64,
    bbox: Box3,
}

/// A box (min, max).
type Box3 = ([f64; 3], [f64; 3]);

/// The box of no point (min > max).
const EMPTY_BOX: Box3 = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);

/// Grows `b` to hold `p`.
fn grow(b: &mut Box3, p: &[f64; 3]) {
    for ((lo, hi), &x) in b.0.iter_mut().zip(b.1.iter_mut()).zip(p) {
        *lo = lo.min(x);
        *hi = hi.max(x);
    }
}

/// A file error naming the file.
fn file_error(path: &Path, action: &'static str, source: std::io::Error) -> IoError {
    IoError::File {
        path: path.to_path_buf(),
        action,
        source,
    }
}

impl Spill {
    /// A spill in a new temporary directory inside `dir`.
    pub(super) fn create(dir: &Path) -> Result<Spill, IoError> {
        let scratch = tempfile::Builder::new()
            .prefix(SCRATCH_PREFIX)
            .tempdir_in(dir)
            .map_err(|e| file_error(dir, "create a temporary directory in", e))?;
        let path = scratch.path().join("spill.bin");
        let file = File::create(&path).map_err(|e| file_error(&path, "create", e))?;
        Ok(Spill {
            dir: scratch,
            path,
            out: BufWriter::with_capacity(BUFFER_BYTES, file),
            sample: Sample::new(),
            count: 0,
            bbox: EMPTY_BOX,
        })
    }

    /// The end of the stream: the spill written out.
    pub(super) fn finish(mut self) -> Result<Spilled, IoError> {
        self.out
            .flush()
            .map_err(|e| file_error(&self.path, "write", e))?;
        Ok(Spilled {
            dir: self.dir,
            triangles: self.count,
            bbox: self.bbox,
            sample: self.sample,
            spill: self.path,
        })
    }
}

impl TriangleSink for Spill {
    fn triangle(&mut self, corners: [[f64; 3]; 3]) -> Result<(), IoError> {
        self.sample.offer(self.count, centroid(&corners));
        self.count += 1;
        for p in &corners {
            grow(&mut self.bbox, p);
        }
        write_triangle(&mut self.out, &corners).map_err(|e| file_error(&self.path, "write", e))
    }
}

fn write_triangle(out: &mut impl Write, corners: &[[f64; 3]; 3]) -> std::io::Result<()> {
    let mut bytes = [0u8; TRIANGLE_BYTES];
    for (i, x) in corners.iter().flatten().enumerate() {
        bytes[8 * i..8 * i + 8].copy_from_slice(&x.to_le_bytes());
    }
    out.write_all(&bytes)
}

/// The next triangle of `input`, `None` at its end.
fn read_triangle(input: &mut impl Read) -> std::io::Result<Option<[[f64; 3]; 3]>> {
    let mut bytes = [0u8; TRIANGLE_BYTES];
    match input.read_exact(&mut bytes) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => return Ok(None),
        Err(e) => return Err(e),
    }
    let x = |i: usize| {
        let mut b = [0u8; 8];
        b.copy_from_slice(&bytes[8 * i..8 * i + 8]);
        f64::from_le_bytes(b)
    };
    Ok(Some(std::array::from_fn(|c| {
        std::array::from_fn(|k| x(3 * c + k))
    })))
}

fn write_key(out: &mut impl Write, key: &[u64; 3]) -> std::io::Result<()> {
    for x in key {
        out.write_all(&x.to_le_bytes())?;
    }
    Ok(())
}

fn read_key(input: &mut impl Read) -> std::io::Result<Option<[u64; 3]>> {
    let mut bytes = [0u8; KEY_BYTES];
    match input.read_exact(&mut bytes) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => return Ok(None),
        Err(e) => return Err(e),
    }
    Ok(Some(std::array::from_fn(|k| {
        let mut b = [0u8; 8];
        b.copy_from_slice(&bytes[8 * k..8 * k + 8]);
        u64::from_le_bytes(b)
    })))
}

/// A tile's file of triangles, and what routing learnt of it.
struct Bucket {
    path: PathBuf,
    triangles: usize,
}

/// The spilled triangles cut into `tiles` tiles, ready to be built one at a time.
pub(super) struct Routed {
    _dir: tempfile::TempDir,
    buckets: Vec<Bucket>,
    /// Each tile's sorted border positions' file.
    borders: Vec<PathBuf>,
    /// Distinct positions the triangles use.
    pub(super) distinct_positions: usize,
}

impl Spilled {
    /// Cuts the spilled triangles into `tiles` tiles (at least 1, at most one per
    /// triangle), each to its own file, and finds their borders.
    pub(super) fn route(self, tiles: usize) -> Result<Routed, IoError> {
        let Spilled {
            dir,
            triangles,
            sample,
            spill,
            ..
        } = self;
        let tiles = tiles.clamp(1, (triangles as usize).max(1));
        open_files_for(tiles, dir.path().parent().unwrap_or(dir.path()))?;
        let cut = Cut::new(sample, tiles);
        let mut buckets = Vec::with_capacity(tiles);
        let mut outs = Vec::with_capacity(tiles);
        // Smaller buffers when there are many tiles: at most about 64 MiB in all.
        let buffer = (BUFFER_BYTES * 1024 / tiles).clamp(4096, BUFFER_BYTES);
        for k in 0..tiles {
            let path = dir.path().join(format!("tile-{k}.bin"));
            let file = File::create(&path).map_err(|e| file_error(&path, "create", e))?;
            outs.push(BufWriter::with_capacity(buffer, file));
            buckets.push(Bucket { path, triangles: 0 });
        }
        let file = File::open(&spill).map_err(|e| file_error(&spill, "read", e))?;
        let mut input = BufReader::with_capacity(BUFFER_BYTES, file);
        let mut number = 0u64;
        while let Some(corners) =
            read_triangle(&mut input).map_err(|e| file_error(&spill, "read", e))?
        {
            let k = cut.tile_of(centroid(&corners), number);
            number += 1;
            let bucket = &mut buckets[k];
            write_triangle(&mut outs[k], &corners)
                .map_err(|e| file_error(&bucket.path, "write", e))?;
            bucket.triangles += 1;
        }
        drop(input);
        std::fs::remove_file(&spill).map_err(|e| file_error(&spill, "remove", e))?;
        for (out, bucket) in outs.into_iter().zip(&buckets) {
            out.into_inner()
                .map_err(|e| file_error(&bucket.path, "write", e.into_error()))?;
        }
        let (borders, distinct_positions) = find_borders(dir.path(), &buckets)?;
        Ok(Routed {
            _dir: dir,
            buckets,
            borders,
            distinct_positions,
        })
    }
}

/// Each tile's sorted distinct positions to a file, then one merge of them: each
/// tile's border positions (used by another tile too) to a file of its own. Returns
/// those files and the number of distinct positions in all.
fn find_borders(dir: &Path, buckets: &[Bucket]) -> Result<(Vec<PathBuf>, usize), IoError> {
    let mut used = Vec::with_capacity(buckets.len());
    for (k, bucket) in buckets.iter().enumerate() {
        let file = File::open(&bucket.path).map_err(|e| file_error(&bucket.path, "read", e))?;
        let mut input = BufReader::with_capacity(BUFFER_BYTES, file);
        let mut keys = Vec::with_capacity(3 * bucket.triangles);
        while let Some(corners) =
            read_triangle(&mut input).map_err(|e| file_error(&bucket.path, "read", e))?
        {
            keys.extend(corners.map(position_key));
        }
        keys.sort_unstable();
        keys.dedup();
        let path = dir.join(format!("used-{k}.bin"));
        let file = File::create(&path).map_err(|e| file_error(&path, "create", e))?;
        let mut out = BufWriter::with_capacity(BUFFER_BYTES, file);
        for key in &keys {
            write_key(&mut out, key).map_err(|e| file_error(&path, "write", e))?;
        }
        out.into_inner()
            .map_err(|e| file_error(&path, "write", e.into_error()))?;
        used.push(path);
    }
    // The merge: the least key of every tile's list at once, in a heap.
    let buffer = (BUFFER_BYTES * 512 / buckets.len().max(1)).clamp(4096, BUFFER_BYTES);
    let mut inputs = Vec::with_capacity(used.len());
    let mut outs = Vec::with_capacity(used.len());
    let mut borders = Vec::with_capacity(used.len());
    for (k, path) in used.iter().enumerate() {
        let file = File::open(path).map_err(|e| file_error(path, "read", e))?;
        inputs.push(BufReader::with_capacity(buffer, file));
        let border = dir.join(format!("border-{k}.bin"));
        let file = File::create(&border).map_err(|e| file_error(&border, "create", e))?;
        outs.push(BufWriter::with_capacity(buffer, file));
        borders.push(border);
    }
    let mut heap = BinaryHeap::new();
    for (k, input) in inputs.iter_mut().enumerate() {
        if let Some(key) = read_key(input).map_err(|e| file_error(&used[k], "read", e))? {
            heap.push(std::cmp::Reverse((key, k)));
        }
    }
    let mut distinct = 0;
    let mut holders = Vec::new();
    while let Some(std::cmp::Reverse((key, k))) = heap.pop() {
        holders.clear();
        holders.push(k);
        while let Some(&std::cmp::Reverse((next, j))) = heap.peek() {
            if next != key {
                break;
            }
            heap.pop();
            holders.push(j);
        }
        distinct += 1;
        if holders.len() > 1 {
            for &j in &holders {
                write_key(&mut outs[j], &key).map_err(|e| file_error(&borders[j], "write", e))?;
            }
        }
        for &j in &holders {
            if let Some(key) =
                read_key(&mut inputs[j]).map_err(|e| file_error(&used[j], "read", e))?
            {
                heap.push(std::cmp::Reverse((key, j)));
            }
        }
    }
    drop(inputs);
    for path in &used {
        std::fs::remove_file(path).map_err(|e| file_error(path, "remove", e))?;
    }
    for (out, path) in outs.into_iter().zip(&borders) {
        out.into_inner()
            .map_err(|e| file_error(path, "write", e.into_error()))?;
    }
    Ok((borders, distinct))
}

impl Routed {
    /// The number of tiles.
    pub(super) fn len(&self) -> usize {
        self.buckets.len()
    }

    /// Tile `k` (as [`Tiling::tile`](super::Tiling::tile) numbers it), and the box of
    /// its triangles' centroids.
    pub(super) fn tile(&self, k: usize) -> Result<(Tile, Box3), IoError> {
        let border_path = &self.borders[k];
        let file = File::open(border_path).map_err(|e| file_error(border_path, "read", e))?;
        let mut input = BufReader::with_capacity(BUFFER_BYTES, file);
        let mut border = Vec::new();
        while let Some(key) =
            read_key(&mut input).map_err(|e| file_error(border_path, "read", e))?
        {
            border.push(key);
        }
        let bucket = &self.buckets[k];
        let file = File::open(&bucket.path).map_err(|e| file_error(&bucket.path, "read", e))?;
        let mut input = BufReader::with_capacity(BUFFER_BYTES, file);
        let mut builder = TileBuilder::default();
        let mut centroids = EMPTY_BOX;
        while let Some(corners) =
            read_triangle(&mut input).map_err(|e| file_error(&bucket.path, "read", e))?
        {
            grow(&mut centroids, &centroid(&corners));
            builder.push(corners.map(|p| (p, border.binary_search(&position_key(p)).is_ok())));
        }
        Ok((builder.finish(), centroids))
    }
}

/// Files a split may hold open beside its tiles' (the input, the spill, the standard
/// streams and what the caller has open).
const SPARE_FILES: u64 = 64;

/// Makes sure the process may open the files a split into `tiles` tiles holds at
/// once (two per tile while the borders are found), raising its soft limit when it
/// can; the error says what is needed and allowed, naming `dir`.
fn open_files_for(tiles: usize, dir: &Path) -> Result<(), IoError> {
    let needed = 2 * tiles as u64 + SPARE_FILES;
    match rlimit::increase_nofile_limit(needed) {
        Ok(allowed) if allowed < needed => Err(file_error(
            dir,
            "split into tiles in",
            std::io::Error::other(format!(
                "{tiles} tiles need about {needed} open files at once, and the system allows \
                 {allowed} (raise it with `ulimit -n`, or ask for fewer tiles)"
            )),
        )),
        // (Where the limit cannot be read, opening the files will tell.)
        _ => Ok(()),
    }
}

/// Removes the temporary directories of earlier splits of `dir` that were killed
/// before they could remove their own (best effort: a directory that cannot be
/// removed stays).
pub(super) fn remove_stale_scratch(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        if name.to_string_lossy().starts_with(SCRATCH_PREFIX) {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}
