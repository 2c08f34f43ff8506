//! The bytes a reader reads: from memory, a file or a gzip stream, in chunks.
//!
//! A reader sees a *window*: the bytes read but not yet consumed. It asks for at least
//! so many ([`Input::fill`]), parses whole records out of the window, and consumes them
//! ([`Input::consume`]); the window is refilled from the source a chunk at a time, so a
//! binary PLY or STL file is read without holding the file, or its decompressed bytes,
//! in memory. OFF, OBJ, ASCII PLY and ASCII STL read whole lines or tokens out of the
//! window the same way ([`super::text::TextStream`]). Data in memory is its own window
//! (nothing is copied), and a reader that needs all of its data at once (glTF) takes the
//! rest with [`Input::rest`].
//!
//! Gzip data is decompressed as it is read, with the caps of [`GZIP_MAX_RATIO`] and
//! [`GZIP_MAX_BYTES`]. Before streaming, the readers decompressed the whole file first,
//! so a corrupt or oversized stream was refused whatever its content: [`Input::finish`]
//! reads a gzip stream to its end to keep that.

use std::borrow::Cow;
use std::io::Read;

use super::{ReadError, ReadErrorKind, BOM, GZIP_MAX_BYTES, GZIP_MAX_RATIO};

/// Bytes asked of the source at a time. Large enough that a read costs little next to
/// parsing what it brings, small enough to be nothing next to a mesh's arrays.
const CHUNK: usize = 1 << 20;

/// Bytes asked of gzip data first; each read asks twice as many, up to the chunk, so a
/// small file does not pay for a buffer of a chunk (measured: about 1% of reading a
/// 50k-triangle gzipped STL). A plain file asks its size first (at most a chunk).
const FIRST_READ: usize = 1 << 16;

/// Where the bytes come from.
enum Source<'a> {
    /// Data in memory: the window is the data not yet consumed, with no copy.
    Memory(&'a [u8]),
    /// A reader of plain data (a file).
    Plain(Box<dyn Read + 'a>),
    /// Gzip data, decompressed as it is read.
    Gzip(Box<Gzip<'a>>),
}

/// A gzip stream and the caps on what it may give.
struct Gzip<'a> {
    decoder: flate2::bufread::MultiGzDecoder<std::io::BufReader<Tracked<'a>>>,
    /// Decompressed bytes so far.
    produced: u64,
    /// The most it may give (see [`GZIP_MAX_RATIO`]).
    limit: u64,
}

/// A reader that keeps the error it gave, so that an error of the file under a gzip
/// decoder can be told apart from the decoder's own (corrupt data).
struct Tracked<'a> {
    inner: Box<dyn Read + 'a>,
    error: Option<std::io::Error>,
}

impl Read for Tracked<'_> {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        self.inner.read(out).map_err(|e| {
            let kind = e.kind();
            // An interruption is retried, not kept.
            if kind != std::io::ErrorKind::Interrupted {
                self.error = Some(e);
            }
            std::io::Error::from(kind)
        })
    }
}

/// Mesh data being read: a window over the source and the place of the window's first
/// byte in the data (for error locations).
pub(crate) struct Input<'a> {
    source: Source<'a>,
    /// The window is `buf[start..end]` (readers only; `buf`'s whole length is
    /// initialised, so reading into it needs no unsafe code).
    buf: Vec<u8>,
    start: usize,
    end: usize,
    /// Offset in the data of the window's first byte.
    offset: u64,
    /// Whether the source has given its last byte: the window is all that is left.
    eof: bool,
    /// Bytes asked of the source at a time, at most ([`CHUNK`]; smaller in tests).
    chunk: usize,
    /// Bytes asked of the source by the next read (from [`FIRST_READ`] up to `chunk`).
    step: usize,
    /// The most bytes the data can have (see [`Input::could_hold`]): exact in memory,
    /// the file's size for a plain file, unknown (`None`) for gzip.
    expected: Option<u64>,
    /// The first error of the source, given again by every later call.
    failure: Option<ReadError>,
    /// An error of the operating system reading the file: the caller reports it as
    /// such ([`Input::take_file_error`]), not as a problem of the content.
    file_error: Option<std::io::Error>,
}

impl<'a> Input<'a> {
    /// Data in memory, decompressed as it is read when it starts with the gzip magic.
    pub(crate) fn detect(data: &'a [u8]) -> Input<'a> {
        if is_gzip(data) {
            Input::gzip(Box::new(data), data.len() as u64, CHUNK)
        } else {
            Input::plain(data)
        }
    }

    /// Data in memory, taken as it is.
    pub(crate) fn plain(data: &'a [u8]) -> Input<'a> {
        Input::new(Source::Memory(data), true, Some(data.len() as u64), CHUNK)
    }

    /// The data of a file, decompressed as it is read when it starts with the gzip
    /// magic.
    pub(crate) fn file(file: std::fs::File) -> std::io::Result<Input<'static>> {
        let meta = file.metadata()?;
        if !meta.is_file() {
            // A pipe or a device has no size beforehand, and gzip's cap needs the
            // compressed size: its bytes are read first, as they all were before
            // streaming.
            let mut data = Vec::new();
            let mut file = file;
            file.read_to_end(&mut data)?;
            let len = data.len() as u64;
            return Input::reader(Box::new(std::io::Cursor::new(data)), len, CHUNK);
        }
        Input::reader(Box::new(file), meta.len(), CHUNK)
    }

    /// The data of `reader`, decompressed as it is read when it starts with the gzip
    /// magic; bytes are asked of the reader `chunk` at a time. `len` is the size of
    /// what the reader gives: for gzip data it must be exact (it sets the cap on what
    /// the data may decompress to); for plain data it must be at least the size (an
    /// upper bound): it is [`Input::could_hold`]'s, which sizes reservations and the
    /// buffer's growth, and on which the STL reader decides whether text could be a
    /// binary file's size.
    pub(crate) fn reader(
        mut reader: Box<dyn Read + 'a>,
        len: u64,
        chunk: usize,
    ) -> std::io::Result<Input<'a>> {
        let mut magic = [0u8; 2];
        let mut got = 0;
        while got < magic.len() {
            match reader.read(&mut magic[got..]) {
                Ok(0) => break,
                Ok(n) => got += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
        let head = magic.get(..got).unwrap_or_default().to_vec();
        let whole: Box<dyn Read + 'a> = Box::new(std::io::Cursor::new(head).chain(reader));
        Ok(if is_gzip(&magic[..got]) {
            Input::gzip(whole, len, chunk)
        } else {
            let mut input = Input::new(Source::Plain(whole), false, Some(len), chunk);
            // A file smaller than a chunk is read in one read into a buffer of its
            // size, not in reads doubling from `FIRST_READ` (the mannequin OFF, 1 MB:
            // see BENCHMARKS.md, "Loading").
            input.step = usize::try_from(len)
                .unwrap_or(usize::MAX)
                .clamp(1, input.chunk);
            input
        })
    }

    fn gzip(compressed: Box<dyn Read + 'a>, len: u64, chunk: usize) -> Input<'a> {
        let limit = len
            .saturating_mul(GZIP_MAX_RATIO)
            .saturating_add(1 << 16)
            .min(GZIP_MAX_BYTES);
        let tracked = Tracked {
            inner: compressed,
            error: None,
        };
        let decoder = flate2::bufread::MultiGzDecoder::new(std::io::BufReader::with_capacity(
            1 << 16,
            tracked,
        ));
        let gzip = Gzip {
            decoder,
            produced: 0,
            limit,
        };
        Input::new(Source::Gzip(Box::new(gzip)), false, None, chunk)
    }

    fn new(source: Source<'a>, eof: bool, expected: Option<u64>, chunk: usize) -> Input<'a> {
        Input {
            source,
            buf: Vec::new(),
            start: 0,
            end: 0,
            offset: 0,
            eof,
            chunk: chunk.max(1),
            step: chunk.clamp(1, FIRST_READ),
            expected,
            failure: None,
            file_error: None,
        }
    }

    /// The bytes read and not yet consumed.
    #[inline]
    pub(crate) fn window(&self) -> &[u8] {
        match &self.source {
            Source::Memory(rest) => rest,
            _ => self.buf.get(self.start..self.end).unwrap_or_default(),
        }
    }

    /// Offset in the data of the window's first byte.
    pub(crate) fn offset(&self) -> u64 {
        self.offset
    }

    /// Whether the window holds all the data that is left.
    #[inline]
    pub(crate) fn at_end(&self) -> bool {
        self.eof
    }

    /// The most bytes the rest of the data can hold, as far as is known: an upper bound
    /// of its size (readers rely on it), which bounds the room reserved for what a
    /// header claims. Exact in memory, the rest of the file's size for a plain file
    /// (the size given to [`Input::reader`]), and for gzip (whose size is known only
    /// at its end) the rest of what its cap allows. (Reserving for gzip data only as it arrives, and
    /// growing, measured 10% slower on a 2M-triangle binary PLY; what is reserved and
    /// never filled takes address space, not memory.)
    pub(crate) fn could_hold(&self) -> usize {
        let bound = match &self.source {
            Source::Gzip(gz) => {
                Some(gz.limit.saturating_sub(gz.produced) + self.window().len() as u64)
            }
            _ => self.expected.map(|len| len.saturating_sub(self.offset)),
        };
        bound
            .map_or(usize::MAX, |b| usize::try_from(b).unwrap_or(usize::MAX))
            .max(self.window().len())
    }

    /// Makes the window hold at least `want` bytes, or all that is left when fewer are.
    pub(crate) fn fill(&mut self, want: usize) -> Result<(), ReadError> {
        if let Some(e) = &self.failure {
            return Err(e.clone());
        }
        while self.window().len() < want && !self.eof {
            self.read_chunk()?;
        }
        Ok(())
    }

    /// Consumes the window's first `n` bytes (at most the window).
    pub(crate) fn consume(&mut self, n: usize) {
        let n = n.min(self.window().len());
        match &mut self.source {
            Source::Memory(rest) => *rest = rest.get(n..).unwrap_or_default(),
            _ => self.start += n,
        }
        self.offset += n as u64;
    }

    /// Consumes up to `n` bytes, reading past the window as needed; returns how many
    /// there were (fewer than `n` only at the end of the data).
    pub(crate) fn skip(&mut self, n: u64) -> Result<u64, ReadError> {
        let mut skipped = 0u64;
        loop {
            let here = self
                .window()
                .len()
                .min(usize::try_from(n - skipped).unwrap_or(usize::MAX));
            self.consume(here);
            skipped += here as u64;
            if skipped == n || self.eof {
                return Ok(skipped);
            }
            self.fill(1)?;
        }
    }

    /// Consumes a UTF-8 byte order mark at the window's start, if there is one, and
    /// makes the data start after it (text formats count places without it).
    pub(crate) fn skip_bom(&mut self) -> Result<bool, ReadError> {
        self.fill(BOM.len())?;
        if !self.window().starts_with(BOM) {
            return Ok(false);
        }
        self.consume(BOM.len());
        self.offset = 0;
        self.expected = self
            .expected
            .map(|len| len.saturating_sub(BOM.len() as u64));
        Ok(true)
    }

    /// All the data not consumed yet, for a reader that parses it at once. In memory
    /// it is borrowed; otherwise it is read whole (with room reserved for a file's
    /// size, as `std::fs::read` does).
    pub(crate) fn rest(&mut self) -> Result<Cow<'a, [u8]>, ReadError> {
        self.fill(0)?;
        let mut data = match &mut self.source {
            Source::Memory(rest) => {
                let data = std::mem::take(rest);
                self.offset += data.len() as u64;
                return Ok(Cow::Borrowed(data));
            }
            _ => Vec::new(),
        };
        let window = self.buf.get(self.start..self.end).unwrap_or_default();
        // A file's size, as `std::fs::read` reserves it (when it can); gzip grows as it
        // arrives.
        let known = self.expected.map_or(0, |len| {
            usize::try_from(len.saturating_sub(self.offset)).unwrap_or(usize::MAX)
        });
        if data
            .try_reserve_exact(window.len().max(known).saturating_add(1))
            .is_err()
        {
            data.reserve(window.len());
        }
        data.extend_from_slice(window);
        self.buf = Vec::new();
        (self.start, self.end) = (0, 0);
        if !self.eof {
            let before = data.len();
            let read = match &mut self.source {
                Source::Memory(_) => Ok(0),
                Source::Plain(reader) => reader.read_to_end(&mut data),
                Source::Gzip(gz) => {
                    let allowed = (gz.limit + 1).saturating_sub(gz.produced);
                    let read = (&mut gz.decoder).take(allowed).read_to_end(&mut data);
                    gz.produced += (data.len() - before) as u64;
                    read
                }
            };
            if let Err(e) = read {
                return Err(self.fail(e));
            }
            self.eof = true;
            self.check_limit()?;
        }
        self.offset += data.len() as u64;
        Ok(Cow::Owned(data))
    }

    /// Reads a gzip stream to its end, so that a corrupt stream or one beyond the caps
    /// is refused as it was when the whole file was decompressed before parsing;
    /// gives the source's first error, if it had one. Other sources are left as they
    /// are: what follows the data a reader wanted cannot change its result.
    pub(crate) fn finish(&mut self) -> Result<(), ReadError> {
        if matches!(self.source, Source::Gzip(_)) {
            self.skip(u64::MAX)?;
        }
        match &self.failure {
            Some(e) => Err(e.clone()),
            None => Ok(()),
        }
    }

    /// The operating system's error reading the file, if there was one (an error of
    /// this input then stands for it and is not to be shown).
    pub(crate) fn take_file_error(&mut self) -> Option<std::io::Error> {
        self.file_error.take()
    }

    /// Reads up to a chunk from the source onto the window's end.
    fn read_chunk(&mut self) -> Result<(), ReadError> {
        let have = self.end - self.start;
        // The most the source can still give, as far as is known. Once it is reached
        // the next read should find the end; if it does not, the bound was wrong (a
        // file that grew) and reads go on as if none were known.
        let unread = self.could_hold() - have;
        let step = if unread > 0 {
            self.step.min(unread)
        } else {
            self.step
        };
        self.step = (2 * self.step).min(self.chunk);
        if self.buf.len() - self.end < step {
            // Move the window to the front, and grow the buffer only when the window
            // itself fills it (a record or line longer than a chunk), so what grows is
            // what has arrived, whatever a header claimed.
            if self.start > 0 {
                self.buf.copy_within(self.start..self.end, 0);
                (self.start, self.end) = (0, have);
            }
            let need = self.end + step;
            if self.buf.len() < need {
                // Room doubles, so a long line costs linear copies, but not past what
                // the rest of the data can hold; and only what this read may fill is
                // written (zeroed): the line costs about itself, not twice it.
                if need > self.buf.capacity() {
                    let mut room = (2 * self.buf.capacity()).max(need);
                    if unread > 0 {
                        room = room.min(self.end.saturating_add(unread)).max(need);
                    }
                    self.buf.reserve_exact(room - self.buf.len());
                }
                self.buf.resize(need, 0);
            }
        }
        let space = self.end..self.buf.len().min(self.end + step);
        let read = match &mut self.source {
            Source::Memory(_) => Ok(0),
            Source::Plain(reader) => reader.read(&mut self.buf[space]),
            Source::Gzip(gz) => {
                // One byte past the limit is enough to know it is passed.
                let allowed = (gz.limit + 1).saturating_sub(gz.produced);
                let len = space
                    .len()
                    .min(usize::try_from(allowed).unwrap_or(usize::MAX));
                let read = gz
                    .decoder
                    .read(&mut self.buf[space.start..space.start + len]);
                if let Ok(n) = read {
                    gz.produced += n as u64;
                }
                read
            }
        };
        match read {
            Ok(0) => self.eof = true,
            Ok(n) => self.end += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(self.fail(e)),
        }
        self.check_limit()
    }

    /// Refuses gzip data beyond its cap.
    fn check_limit(&mut self) -> Result<(), ReadError> {
        let Source::Gzip(gz) = &self.source else {
            return Ok(());
        };
        if gz.produced <= gz.limit {
            return Ok(());
        }
        let limit = gz.limit;
        let e = ReadError::new(
            ReadErrorKind::Gzip {
                detail: format!(
                    "decompresses to more than {limit} bytes \
                     ({GZIP_MAX_RATIO}x the compressed size, at most {GZIP_MAX_BYTES})"
                ),
            },
            None,
        );
        self.failure = Some(e.clone());
        Err(e)
    }

    /// Records the source's error `e` and gives the error that stands for it.
    fn fail(&mut self, e: std::io::Error) -> ReadError {
        let gzip = match &mut self.source {
            Source::Gzip(gz) => Some((gz.decoder.get_mut().get_mut().error.take(), gz.produced)),
            _ => None,
        };
        let error = match gzip {
            Some((None, produced)) => ReadError::new(
                ReadErrorKind::Gzip {
                    detail: format!("corrupt data after {produced} decompressed bytes: {e}"),
                },
                None,
            ),
            Some((Some(file), _)) => self.file_failure(file),
            None => self.file_failure(e),
        };
        self.failure = Some(error.clone());
        error
    }

    /// Keeps a file error for [`Input::take_file_error`]; the error returned stands for
    /// it in the readers (whose errors are about the content).
    fn file_failure(&mut self, e: std::io::Error) -> ReadError {
        let error = ReadError::new(
            ReadErrorKind::Malformed {
                detail: format!("the data could not be read further: {e}"),
            },
            None,
        );
        self.file_error = Some(e);
        error
    }
}

/// Whether data starts with the gzip magic bytes.
fn is_gzip(bytes: &[u8]) -> bool {
    bytes.starts_with(&[0x1f, 0x8b])
}

#[cfg(test)]
pub(crate) mod tests {
    //! Reading in small chunks, from a reader whose size is known or not, gives what
    //! reading the same bytes from memory gives (where a window is all the data), on
    //! inputs whose records straddle chunks, truncated ones, wrong and huge counts; and
    //! a streaming read gives what the ordinary read gives ([`check`], which the
    //! readers' own tests call too).

    use std::io::Write;

    use super::*;
    use crate::attributes::{Attributes, Channel, ChannelKind};
    use crate::io::{read_bytes, read_input, write_to, Format, LoadedMesh};
    use crate::IndexedMesh;

    /// Chunk sizes that cut records, list counts and scalars everywhere.
    const CHUNKS: [usize; 6] = [1, 2, 3, 7, 50, 4096];

    /// `data` read from a reader `chunk` bytes at a time; `sized`: with the data's size
    /// known beforehand, as for a file (otherwise only an upper bound of it).
    fn chunked(
        data: &[u8],
        format: Format,
        chunk: usize,
        sized: bool,
    ) -> Result<LoadedMesh, ReadError> {
        // Gzip's cap needs the compressed size; plain data's needs to be an upper bound
        // (a file's size), which here is exact or not.
        let len = if sized || is_gzip(data) {
            data.len() as u64
        } else {
            2 * data.len() as u64 + 4096
        };
        let mut input = Input::reader(Box::new(data), len, chunk).expect("memory reads");
        read_input(&mut input, format, None)
    }

    /// The same result in memory and chunked, and streamed ([`check_streamed`]). A
    /// corrupt gzip stream's message says how many bytes were decompressed before the
    /// error, which depends on how much was asked at a time: only its text without
    /// digits is compared.
    pub(crate) fn check(data: &[u8], format: Format, chunk: usize, sized: bool, what: &str) {
        let whole = read_bytes(data, format);
        let parts = chunked(data, format, chunk, sized);
        let gzip_corrupt = |r: &Result<LoadedMesh, ReadError>| match r {
            Err(e) => {
                matches!(e.kind(), ReadErrorKind::Gzip { detail } if detail.starts_with("corrupt"))
                    .then(|| e.to_string().replace(|c: char| c.is_ascii_digit(), ""))
            }
            Ok(_) => None,
        };
        match (gzip_corrupt(&whole), gzip_corrupt(&parts)) {
            (Some(a), Some(b)) => assert_eq!(a, b, "{what}, chunk {chunk}, sized {sized}"),
            _ => assert_eq!(parts, whole, "{what}, chunk {chunk}, sized {sized}"),
        }
        check_streamed(data, format, chunk, sized, &whole, what);
    }

    /// Every triangle a streaming read hands on, as its corners' bits.
    #[derive(Default)]
    struct Collect(Vec<[[u64; 3]; 3]>);

    impl crate::io::TriangleSink for Collect {
        fn triangle(&mut self, corners: [[f64; 3]; 3]) -> Result<(), crate::io::IoError> {
            self.0.push(corners.map(|p| p.map(f64::to_bits)));
            Ok(())
        }
    }

    /// A streaming read of `data` in chunks fails as the ordinary read `whole` did,
    /// or hands on that mesh's triangles (in its order, but for triangles that waited
    /// for their vertices) and counts its vertices.
    fn check_streamed(
        data: &[u8],
        format: Format,
        chunk: usize,
        sized: bool,
        whole: &Result<LoadedMesh, ReadError>,
        what: &str,
    ) {
        let len = if sized || is_gzip(data) {
            data.len() as u64
        } else {
            2 * data.len() as u64 + 4096
        };
        let mut input = Input::reader(Box::new(data), len, chunk).expect("memory reads");
        let mut sink = Collect::default();
        let streamed = crate::io::stream_input(&mut input, format, None, &mut sink);
        let at = format!("{what}, chunk {chunk}, sized {sized}, streamed");
        match (whole, streamed) {
            (Ok(loaded), Ok(streamed)) => {
                let mesh = &loaded.mesh;
                let mut expected: Vec<[[u64; 3]; 3]> = mesh
                    .triangles
                    .iter()
                    .map(|t| t.map(|v| mesh.positions[v as usize].map(f64::to_bits)))
                    .collect();
                let mut got = sink.0;
                if got != expected {
                    // Only triangles that waited for their vertices come out of order.
                    got.sort_unstable();
                    expected.sort_unstable();
                    assert_eq!(got, expected, "{at}");
                }
                assert_eq!(streamed.triangles, mesh.triangle_count(), "{at}");
                assert_eq!(streamed.vertices, mesh.vertex_count(), "{at}");
                assert_eq!(streamed.notes, loaded.notes, "{at}");
                assert_eq!(streamed.attributes, mesh.attributes.names(), "{at}");
            }
            (Err(e), Err(crate::io::StreamError::Read(s))) => {
                // (A corrupt gzip stream's byte count depends on the chunks.)
                let digits =
                    |e: &ReadError| e.to_string().replace(|c: char| c.is_ascii_digit(), "");
                assert_eq!(digits(&s), digits(e), "{at}");
            }
            (whole, streamed) => panic!(
                "{at}: read {:?}, streamed {:?}",
                whole.as_ref().map(|l| l.mesh.triangle_count()),
                streamed.map(|s| s.triangles).map_err(|e| match e {
                    crate::io::StreamError::Read(e) => e.to_string(),
                    crate::io::StreamError::Sink(e) => e.to_string(),
                })
            ),
        }
    }

    /// `data` read every way a caller can, plain and gzipped: from memory
    /// (`read_bytes`), from a file (`read_path`) and from a reader in chunks of each
    /// size of [`CHUNKS`], with the size exact or only an upper bound; each result
    /// named, an error as its message.
    fn every_way(data: &[u8], format: Format) -> Vec<(String, Result<LoadedMesh, String>)> {
        let dir = tempfile::tempdir().expect("a temporary directory");
        let ext = match format {
            Format::Off => "off",
            Format::Ply => "ply",
            Format::Stl => "stl",
            Format::Obj => "obj",
            _ => unreachable!("the streamed formats"),
        };
        let mut got = Vec::new();
        for (kind, data) in [("plain", data.to_vec()), ("gzipped", gzip(data))] {
            got.push((
                format!("{kind} read_bytes"),
                read_bytes(&data, format).map_err(|e| e.to_string()),
            ));
            let path = dir.path().join(format!("{kind}.{ext}"));
            std::fs::write(&path, &data).expect("a temporary file");
            let read = crate::io::read_path(&path).map_err(|e| match e {
                crate::io::IoError::Read { source, .. } => source.to_string(),
                other => other.to_string(),
            });
            got.push((format!("{kind} read_path"), read));
            for chunk in CHUNKS {
                for sized in [true, false] {
                    got.push((
                        format!("{kind} in chunks of {chunk}, sized {sized}"),
                        chunked(&data, format, chunk, sized).map_err(|e| e.to_string()),
                    ));
                }
            }
        }
        got
    }

    /// The text readers' edge cases give, every way they are read (so with `\r\n`
    /// and tokens cut between reads), what the readers that parsed all the bytes at
    /// once gave: the expected values were printed by 69c3ccb's `read_bytes`. A last
    /// line that is not UTF-8 without a line break, a byte order mark, the end of the
    /// data inside a token (valid, a bad number, a cut list, a cut keyword).
    #[test]
    fn text_edge_cases_give_what_the_whole_buffer_readers_gave() {
        let cases: [(Format, &[u8], &str); 15] = [
            (
                Format::Off,
                &b"\xef\xbb\xbfOFF\r\n3 1 0\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\njunk caf\xe9"[..],
                "OK tris=[[0, 1, 2]] pos=[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] notes=ReadNotes { skipped_lines: 1, skipped_properties: 0, skipped_primitives: 0, non_utf8_lines: 1, byte_order_mark: true }",
            ),
            (
                Format::Off,
                &b"OFF\r\n3 1 0\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1"[..],
                "ERR line 6: face 0: expected 3 vertex indices, found 2",
            ),
            (
                Format::Off,
                &b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0.5e"[..],
                "ERR line 5: vertex 2: bad coordinate \"0.5e\"",
            ),
            (
                Format::Off,
                &b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2"[..],
                "OK tris=[[0, 1, 2]] pos=[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] notes=ReadNotes { skipped_lines: 0, skipped_properties: 0, skipped_primitives: 0, non_utf8_lines: 0, byte_order_mark: false }",
            ),
            (
                Format::Off,
                &b"OFF\r\n3 1 0\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n# caf\xe9"[..],
                "OK tris=[[0, 1, 2]] pos=[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] notes=ReadNotes { skipped_lines: 0, skipped_properties: 0, skipped_primitives: 0, non_utf8_lines: 1, byte_order_mark: false }",
            ),
            (
                Format::Ply,
                &b"\xef\xbb\xbfply\r\nformat ascii 1.0\r\ncomment caf\xe9\r\nelement vertex 3\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n"[..],
                "OK tris=[[0, 1, 2]] pos=[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] notes=ReadNotes { skipped_lines: 0, skipped_properties: 0, skipped_primitives: 0, non_utf8_lines: 1, byte_order_mark: true }",
            ),
            (
                Format::Ply,
                &b"ply\r\nformat ascii 1.0\r\ncomment caf\xe9\r\nelement vertex 3\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1"[..],
                "ERR line 14: unexpected end of file in face 0: its list claims 3 items, more than the rest of the file can hold",
            ),
            (
                Format::Ply,
                &b"ply\r\nformat ascii 1.0\r\ncomment caf\xe9\r\nelement vertex 3\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n0 0 0\r\n1 0 0\r\n0 1 0.5e"[..],
                "ERR line 13: vertex 2: bad coordinate \"0.5e\"",
            ),
            (
                Format::Ply,
                &b"ply\r\nformat ascii 1.0\r\ncomment caf\xe9\r\nelement vertex 3\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2"[..],
                "OK tris=[[0, 1, 2]] pos=[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] notes=ReadNotes { skipped_lines: 0, skipped_properties: 0, skipped_primitives: 0, non_utf8_lines: 1, byte_order_mark: false }",
            ),
            (
                Format::Ply,
                &b"ply\r\nformat ascii 1.0\r\ncomment caf\xe9\r\nelement vertex 3\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\ncaf\xe9"[..],
                "OK tris=[[0, 1, 2]] pos=[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] notes=ReadNotes { skipped_lines: 0, skipped_properties: 0, skipped_primitives: 0, non_utf8_lines: 1, byte_order_mark: false }",
            ),
            (
                Format::Stl,
                &b"\xef\xbb\xbfsolid x\r\n facet normal 0 0 1\r\n  outer loop\r\n   vertex 0 0 0\r\n   vertex 1 0 0\r\n   vertex 0 1 0\r\n  endloop\r\n endfacet\r\n facet normal 0 0 1\r\n  outer loop\r\n   vertex 0 0 0\r\n   vertex 1 0 0\r\n   vertex 0 1 0\r\n  endloop\r\n endfacet\r\nendsolid caf\xe9"[..],
                "OK tris=[[0, 1, 2], [3, 4, 5]] pos=[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] notes=ReadNotes { skipped_lines: 0, skipped_properties: 0, skipped_primitives: 0, non_utf8_lines: 1, byte_order_mark: true }",
            ),
            (
                Format::Stl,
                &b"solid x\r\n facet normal 0 0 1\r\n  outer loop\r\n   vertex 0 0 0\r\n   vertex 1 0 0\r\n   vertex 0 1 0\r\n  endloop\r\n endfacet\r\n facet normal 0 0 1\r\n  outer loop\r\n   vertex 0 0 0\r\n   vertex 1 0 0\r\n   vertex 0 1 0\r\n  endloop\r\n endfacet\r\nendsolid"[..],
                "OK tris=[[0, 1, 2], [3, 4, 5]] pos=[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] notes=ReadNotes { skipped_lines: 0, skipped_properties: 0, skipped_primitives: 0, non_utf8_lines: 0, byte_order_mark: false }",
            ),
            (
                Format::Stl,
                &b"solid x\r\n facet normal 0 0 1\r\n  outer loop\r\n   vertex 0 0 0\r\n   vertex 1 0 0\r\n   vertex 0 1 0\r\n  endloop\r\n endfacet\r\n facet normal 0 0 1\r\n  outer loop\r\n   vertex 0 0 0\r\n   vertex 1 0 0\r\n   vertex 0 1 0\r\n  endloop\r\n endfacet\r\n facet normal 0 0 1\r\n  outer loop\r\n   vertex 0 0 0\r\n   vertex 1 0 0\r\n   vertex 0 1 0.5e"[..],
                "ERR line 20: facet 2, vertex 2: coordinate 2 is \"0.5e\", not a number",
            ),
            (
                Format::Stl,
                &b"solid x\r\n facet normal 0 0 1\r\n  outer loop\r\n   vertex 0 0 0\r\n   vertex 1 0 0\r\n   vertex 0 1 0\r\n  endloop\r\n endfacet\r\n facet normal 0 0 1\r\n  outer loop\r\n   vertex 0 0 0\r\n   vertex 1 0 0\r\n   vertex 0 1 0\r\n  endloop\r\n endfacet\r\n facet normal 0 0 1\r\n  outer loop\r\n   vertex 0 0 0\r\n   vertex 1 0 0\r\n   vertex 0 1"[..],
                "ERR line 20: facet 2, vertex 2: coordinate 2 is \"\", not a number",
            ),
            (
                Format::Stl,
                &b"solid x\r\n facet normal 0 0 1\r\n  outer loop\r\n   vertex 0 0 0\r\n   vertex 1 0 0\r\n   vertex 0 1 0\r\n  endloop\r\n endfacet\r\n facet normal 0 0 1\r\n  outer loop\r\n   vertex 0 0 0\r\n   vertex 1 0 0\r\n   vertex 0 1 0\r\n  endloop\r\n endfacet\r\n facet normal 0 0 1\r\n  outer loop\r\n   vertex 0 0 0\r\n   vertex 1 0 0\r\n   vertex 0 1 0\r\n  endlo"[..],
                "ERR line 21: unexpected end of file inside facet 2",
            ),
        ];
        for (format, data, want) in cases {
            for (how, got) in every_way(data, format) {
                let got = match got {
                    Ok(l) => format!(
                        "OK tris={:?} pos={:?} notes={:?}",
                        l.mesh.triangles, l.mesh.positions, l.notes
                    ),
                    Err(e) => format!("ERR {e}"),
                };
                assert_eq!(got, want, "{how}: {data:?}");
            }
        }
    }

    /// ASCII STL whose last line is not UTF-8 and has no line break: that line is
    /// counted in `non_utf8_lines`, with and without a byte order mark, as the readers
    /// that parsed all the bytes at once counted it (values from 69c3ccb).
    #[test]
    fn an_ascii_stl_last_line_without_a_line_break_is_counted() {
        let facet = b"facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  \
                      vertex 0 1 0\n endloop\nendfacet\n";
        let facets = facet.repeat(3);
        let named = [&b"solid caf\xe9\n"[..], &facets, b"endsolid caf\xe9"].concat();
        let junk = [&b"solid x\n"[..], &facets, b"endsolid x\n\xff\xfe junk"].concat();
        for (data, non_utf8, skipped) in [(named, 2, 0), (junk, 1, 1)] {
            for bom in [false, true] {
                let data = if bom {
                    [BOM, &data].concat()
                } else {
                    data.clone()
                };
                for (how, got) in every_way(&data, Format::Stl) {
                    let got = got.unwrap_or_else(|e| panic!("{how}: {e}"));
                    assert_eq!(got.mesh.triangles.len(), 3, "{how}");
                    let notes = &got.notes;
                    assert_eq!(
                        (
                            notes.non_utf8_lines,
                            notes.skipped_lines,
                            notes.byte_order_mark
                        ),
                        (non_utf8, skipped, bom),
                        "{how}, bom {bom}"
                    );
                }
            }
        }
    }

    fn gzip(data: &[u8]) -> Vec<u8> {
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        enc.write_all(data).expect("memory writes");
        enc.finish().expect("memory writes")
    }

    /// A 6 x 5 grid with texture coordinates, an RGBA colour, a generic channel and a
    /// face colour, as the PLY writer writes it (binary little endian, `double` x y z).
    fn written_ply() -> Vec<u8> {
        let (w, h) = (6u32, 5u32);
        let positions: Vec<[f64; 3]> = (0..w * h)
            .map(|i| [f64::from(i % w), f64::from(i / w), f64::from(i) * 0.01])
            .collect();
        let mut triangles = Vec::new();
        for y in 0..h - 1 {
            for x in 0..w - 1 {
                let a = y * w + x;
                triangles.push([a, a + 1, a + w]);
                triangles.push([a + 1, a + w + 1, a + w]);
            }
        }
        let n = positions.len();
        let per_vertex = |dimension: usize, f: &dyn Fn(usize, usize) -> f32| -> Vec<f32> {
            (0..n * dimension)
                .map(|i| f(i / dimension, i % dimension))
                .collect()
        };
        let uv = Channel::new(
            ChannelKind::TexCoord,
            per_vertex(2, &|v, k| (v * (k + 1)) as f32 / 64.0),
            triangles.clone(),
        );
        let colour = Channel::new(
            ChannelKind::Color,
            per_vertex(4, &|v, k| ((v * 7 + k * 50) % 256) as f32 / 255.0),
            triangles.clone(),
        )
        .with_dimension(4);
        let quality = Channel::new(
            ChannelKind::Generic,
            per_vertex(1, &|v, _| v as f32 * 0.5),
            triangles.clone(),
        )
        .with_name("quality");
        let t = triangles.len();
        let face_colour = Channel::new(
            ChannelKind::Color,
            (0..3 * t)
                .map(|i| ((i * 13) % 256) as f32 / 255.0)
                .collect(),
            (0..t as u32).map(|f| [f; 3]).collect(),
        )
        .with_name("face_colour");
        let mesh = IndexedMesh::new(positions, triangles).with_attributes(Attributes {
            channels: vec![uv, colour, quality, face_colour],
            ..Attributes::default()
        });
        let mut out = Vec::new();
        write_to(&mut out, &mesh, Format::Ply).expect("memory writes");
        out
    }

    /// Big endian, faces before vertices, a quad, `uint` list counts, a skipped element
    /// of fixed records and one with lists, a byte order mark and CRLF line ends.
    fn big_endian_ply() -> Vec<u8> {
        let header = "ply\r\nformat binary_big_endian 1.0\r\ncomment caf\u{e9}\r\n\
            element face 3\r\nproperty list uint uint vertex_indices\r\n\
            element junk 4\r\nproperty short a\r\nproperty short b\r\n\
            element vertex 5\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\n\
            property short level\r\n\
            element edge 2\r\nproperty int id\r\nproperty list uchar short stuff\r\n\
            end_header\r\n";
        let mut data = b"\xEF\xBB\xBF".to_vec();
        data.extend(header.as_bytes());
        for face in [&[0u32, 1, 2, 3][..], &[0, 1, 4], &[1, 2, 4]] {
            data.extend((face.len() as u32).to_be_bytes());
            face.iter().for_each(|i| data.extend(i.to_be_bytes()));
        }
        for k in 0..4i16 {
            data.extend(k.to_be_bytes());
            data.extend((-k).to_be_bytes());
        }
        for (v, p) in [
            [0.0f32, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.5, 0.5, 1.0],
        ]
        .iter()
        .enumerate()
        {
            p.iter().for_each(|c| data.extend(c.to_be_bytes()));
            data.extend((v as i16 * 100).to_be_bytes());
        }
        for id in 0..2i32 {
            data.extend(id.to_be_bytes());
            data.push(3);
            (0..3i16).for_each(|s| data.extend(s.to_be_bytes()));
        }
        data
    }

    /// A header longer than the prefix first looked at for `end_header`.
    fn long_header_ply() -> Vec<u8> {
        let comments = "comment padding padding padding padding padding padding\n".repeat(2000);
        let header = format!(
            "ply\nformat binary_little_endian 1.0\n{comments}element vertex 3\n\
             property float x\nproperty float y\nproperty float z\n\
             element face 1\nproperty list uchar int vertex_indices\nend_header\n"
        );
        assert!(header.len() > super::super::ply::HEADER_PREFIX);
        let mut data = header.into_bytes();
        for c in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
            data.extend(c.to_le_bytes());
        }
        data.push(3);
        (0..3i32).for_each(|i| data.extend(i.to_le_bytes()));
        data
    }

    fn written_stl(header: &[u8]) -> Vec<u8> {
        let positions: Vec<[f64; 3]> = (0..12)
            .map(|i| [f64::from(i), f64::from(i * i), 1.0])
            .collect();
        let triangles: Vec<[u32; 3]> = (0..10).map(|i| [i, i + 1, i + 2]).collect();
        let mut out = Vec::new();
        write_to(
            &mut out,
            &IndexedMesh::new(positions, triangles),
            Format::Stl,
        )
        .expect("memory writes");
        out[..header.len()].copy_from_slice(header);
        out
    }

    /// `data` with the first `old` replaced by `new`.
    fn replaced(data: &[u8], old: &[u8], new: &[u8]) -> Vec<u8> {
        let at = data
            .windows(old.len())
            .position(|w| w == old)
            .expect("present");
        [&data[..at], new, &data[at + old.len()..]].concat()
    }

    /// The inputs that [`cases`] varies (gzipped, twice gzipped, with more after).
    fn bases() -> Vec<(&'static str, Vec<u8>, Format)> {
        let ascii =
            b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
            property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
            0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"
                .to_vec();
        let mut bases = vec![
            ("written", written_ply(), Format::Ply),
            ("big endian", big_endian_ply(), Format::Ply),
            ("long header", long_header_ply(), Format::Ply),
            ("ascii", ascii, Format::Ply),
            ("stl", written_stl(b"binary"), Format::Stl),
            ("stl solid", written_stl(b"solid but binary"), Format::Stl),
        ];
        bases.extend(text_bases());
        bases
    }

    /// Text files whose lines straddle chunks: comments, line ends, a byte order mark,
    /// bytes that are not UTF-8, no final line break, a line longer than a chunk.
    fn text_bases() -> Vec<(&'static str, Vec<u8>, Format)> {
        let long_comment = format!("# {}\n", "long ".repeat(2000));
        vec![
            (
                "off",
                b"OFF\n# a comment\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n".to_vec(),
                Format::Off,
            ),
            (
                "coff, bom, crlf, latin-1, no final line break",
                b"\xEF\xBB\xBFCOFF\r\n# caf\xe9\r\n\r\n4 1 0\r\n0 0 0 255 0 0\r\n1 0 0 0 255 0\r\n\
                  1 1 0 0 0 255 # blue\r\n0 1 0 9 9 9\r\n4 0 1 2 3 1 0 0\r\nafter \xff\r\nmore"
                    .to_vec(),
                Format::Off,
            ),
            (
                "off, counts on their own line, a long comment",
                format!(
                    "{long_comment}NOFF\n{long_comment}3 1\n0 0 0 0 0 1\n1 0 0 0 0 1\n\
                     0 1 0 0 0 1\n{long_comment}3 0 1 2"
                )
                .into_bytes(),
                Format::Off,
            ),
            (
                "ascii ply, bom, crlf, colours, a quad",
                b"\xEF\xBB\xBFply\r\nformat ascii 1.0\r\ncomment caf\xe9\r\nelement vertex 4\r\n\
                  property float x\r\nproperty float y\r\nproperty float z\r\n\
                  property uchar red\r\nproperty uchar green\r\nproperty uchar blue\r\n\
                  element face 2\r\nproperty list uchar int vertex_indices\r\nend_header\r\n\
                  0 0 0 255 0 0\r\n1 0 0 0 255 0\r\n1 1 0 0 0 255\r\n0 1 0 9 9 9\r\n\
                  4 0 1 2 3\r\n3\t0 1\r\n 2"
                    .to_vec(),
                Format::Ply,
            ),
            (
                // Cut after "9", the list claims more than the rest holds: that error,
                // not the index's.
                "ascii ply, an index out of range",
                b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                  property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                  end_header\n0 0 0\n1 0 0\n0 1 0\n4 0 1 9 2\n"
                    .to_vec(),
                Format::Ply,
            ),
            (
                "ascii stl, bom, crlf, latin-1 names, a quad facet, an unknown word",
                b"\xEF\xBB\xBFsolid caf\xe9 part\r\n facet normal 0 0 1\r\n  outer loop\r\n\
                  \x20  vertex 0 0 0\r\n   vertex 1 0 0\r\n   vertex 1 1 0\r\n   vertex 0 1 0\r\n\
                  \x20 endloop\r\n endfacet\r\n color 1 2 3\r\nendsolid caf\xe9\r\n"
                    .to_vec(),
                Format::Stl,
            ),
            (
                "ascii stl, upper case, no final line break",
                b"SOLID\nFACET NORMAL 0 0 0\nOUTER LOOP\nVERTEX 0 0 0\nVERTEX 1e0 0 0\n\
                  VERTEX 0 1 -0\nENDLOOP\nENDFACET\nfacet normal 0 0 0 outer loop vertex 0 0 1 \
                  vertex 1 0 1 vertex 0 1 1 endloop endfacet\nENDSOLID"
                    .to_vec(),
                Format::Stl,
            ),
            (
                "obj, bom, crlf, continuations, sections, latin-1 names, colours, relative indices",
                b"\xEF\xBB\xBF# caf\xe9\r\nmtllib a b.mtl\r\nv 0 0 0 1 0 0\r\nv 1 0 0 0 1 0\r\n\
                  v 1 1 0 0 0 1\r\nv 0 1 0 1 1 1\r\nvt 0 0\r\nvt 1 0\r\nvt 1 1\r\nvn 0 0 1\r\n\
                  g caf\xe9\r\nusemtl m\r\nf 1/1/1 2/2/1 \\\r\n 3/3/1 4\r\ng b\r\n\
                  f -4//-1 -3//-1 -2//-1\r\ns off\r\nl 1 2\r\nf 1 2 3"
                    .to_vec(),
                Format::Obj,
            ),
            (
                "obj, a long comment, a bad index",
                format!(
                    "{long_comment}v 0 0 0\nv 1 0 0\n{long_comment}v 0 1 0\nf 1 2 3\nf 1 2 0\n"
                )
                .into_bytes(),
                Format::Obj,
            ),
        ]
    }

    /// Every input and its variants, named.
    fn cases() -> Vec<(String, Vec<u8>, Format)> {
        let mut cases = Vec::new();
        let ply = written_ply();
        let big = big_endian_ply();
        let stl = written_stl(b"binary");
        for (name, data, format) in bases() {
            cases.push((format!("{name} gzipped"), gzip(&data), format));
            cases.push((
                format!("{name} twice gzipped"),
                [gzip(&data), gzip(b"more")].concat(),
                format,
            ));
            cases.push((
                format!("{name} with more after"),
                [&data[..], b"\0more"].concat(),
                format,
            ));
            cases.push((name.to_string(), data, format));
        }
        // Counts that disagree with the data, up to the largest accepted and beyond.
        for (old, n) in [(&b"element vertex 30"[..], 30), (b"element face 40", 40)] {
            for count in [
                0,
                1,
                n - 1,
                n + 1,
                2 * n,
                100_000_000,
                1 << 28,
                (1 << 28) + 1,
            ] {
                let new = replaced(
                    &ply,
                    old,
                    format!("{} {count}", String::from_utf8_lossy(&old[..old.len() - 3]))
                        .as_bytes(),
                );
                cases.push((
                    format!("{} as {count}", String::from_utf8_lossy(old)),
                    new,
                    Format::Ply,
                ));
            }
        }
        for (old, count) in [
            (&b"element vertex 5"[..], &b"element vertex 9"[..]),
            (b"element junk 4", b"element junk 9999999"),
            (b"element edge 2", b"element edge 3"),
        ] {
            cases.push((
                String::from_utf8_lossy(count).into_owned(),
                replaced(&big, old, count),
                Format::Ply,
            ));
        }
        // A list that claims more than the rest of the file, as 255 and as 2^32 - 1.
        let body = ply
            .windows(11)
            .position(|w| w == b"end_header\n")
            .expect("a header")
            + 11;
        let first_face = body + 30 * (24 + 8 + 4 + 4);
        let mut claim = ply.clone();
        claim[first_face] = 255;
        cases.push(("list of 255".into(), claim.clone(), Format::Ply));
        cases.push(("list of 255 gzipped".into(), gzip(&claim), Format::Ply));
        let body = big
            .windows(12)
            .position(|w| w == b"end_header\r\n")
            .expect("a header")
            + 12;
        let mut claim = big.clone();
        claim[body..body + 4].copy_from_slice(&u32::MAX.to_be_bytes());
        cases.push(("list of 2^32 - 1".into(), claim, Format::Ply));
        // A coordinate that is not finite, alone and with the file cut after it.
        let mut nan = ply.clone();
        nan[body + 8..body + 16].copy_from_slice(&f64::NAN.to_le_bytes());
        cases.push(("nan".into(), nan.clone(), Format::Ply));
        cases.push((
            "nan, cut".into(),
            nan[..nan.len() - 1].to_vec(),
            Format::Ply,
        ));
        for count in [0u32, 1, 9, 11, 1 << 28, (1 << 28) + 1, u32::MAX] {
            let mut data = stl.clone();
            data[80..84].copy_from_slice(&count.to_le_bytes());
            cases.push((format!("stl count {count}"), data.clone(), Format::Stl));
            cases.push((
                format!("stl count {count} gzipped"),
                gzip(&data),
                Format::Stl,
            ));
        }
        let mut nan = stl.clone();
        nan[84 + 2 * 50 + 16..84 + 2 * 50 + 20].copy_from_slice(&f32::NAN.to_le_bytes());
        cases.push(("stl nan".into(), nan.clone(), Format::Stl));
        cases.push((
            "stl nan, cut".into(),
            nan[..nan.len() - 1].to_vec(),
            Format::Stl,
        ));
        cases.push((
            "stl nan, longer".into(),
            [&nan[..], b"x"].concat(),
            Format::Stl,
        ));
        cases.push((
            "stl after whitespace".into(),
            [&b" ".repeat(5000)[..], b"solid", &stl].concat(),
            Format::Stl,
        ));
        cases
    }

    #[test]
    fn chunked_reading_gives_what_memory_gives() {
        for (name, data, format) in cases() {
            for (k, &chunk) in CHUNKS.iter().enumerate() {
                check(&data, format, chunk, k % 2 == 0, &name);
            }
        }
    }

    /// An ASCII PLY list's items are read as they arrive: when one fails, the rest of
    /// the data decides whether the list claimed more items than it can hold (that
    /// error, as when the whole data was looked at first) or the item's error stands.
    #[test]
    fn an_ascii_list_that_claims_too_much_is_found_when_an_item_fails() {
        let ply = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
            property float y\nproperty float z\nelement face 1\n\
            property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n4 0 1 9 2\n";
        let cut = ply.len() - 3;
        let claims = "line 13: unexpected end of file in face 0: its list claims 4 items, \
                      more than the rest of the file can hold";
        let index = "line 13: face 0 refers to vertex 9, but there are only 3 vertices";
        for (data, want) in [(&ply[..], index), (&ply[..cut], claims)] {
            for chunk in CHUNKS {
                let got = chunked(data, Format::Ply, chunk, true).map(|_| ());
                assert_eq!(got.map_err(|e| e.to_string()), Err(want.to_string()));
            }
        }
    }

    /// A text line longer than a chunk is held whole, and only it: the window's buffer
    /// is written (zero-filled, then read into) up to about the line and a read, not
    /// to twice the line nor to the file's size (here 2.5 MB, of lines gzip cannot
    /// shrink past its cap); and when the line is about all the file holds, its
    /// room is not reserved past the file's end.
    #[test]
    fn a_long_line_costs_the_line_not_the_file() {
        let line = 300_000;
        let off = |after: &str| {
            format!(
                "OFF\n# {}\n3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n{after}",
                "x".repeat(line)
            )
        };
        let many = (0..200_000)
            .map(|i| format!("after {i}\n"))
            .collect::<String>();
        let data = off(&many);
        for data in [data.as_bytes().to_vec(), gzip(data.as_bytes())] {
            let mut input =
                Input::reader(Box::new(&data[..]), data.len() as u64, 4096).expect("memory reads");
            let loaded = read_input(&mut input, Format::Off, None).expect("a valid OFF");
            assert_eq!(loaded.mesh.triangles, vec![[0, 1, 2]]);
            assert_eq!(loaded.notes.skipped_lines, 200_000);
            assert!(input.buf.len() > line, "the line is held whole");
            assert!(input.buf.len() <= line + 3 * 4096, "{}", input.buf.len());
        }
        let data = off("");
        let mut input = Input::reader(Box::new(data.as_bytes()), data.len() as u64, 4096)
            .expect("memory reads");
        read_input(&mut input, Format::Off, None).expect("a valid OFF");
        assert!(
            input.buf.capacity() <= data.len() + 1,
            "{}",
            input.buf.capacity()
        );
    }

    /// A plain file smaller than a chunk is read into one buffer of its size in one
    /// read (after the two bytes that tell gzip), not in reads doubling from
    /// `FIRST_READ`.
    #[test]
    fn a_file_smaller_than_a_chunk_is_read_at_once() {
        let data = vec![b'x'; 200_000];
        let mut input =
            Input::reader(Box::new(&data[..]), data.len() as u64, CHUNK).expect("memory reads");
        input.fill(3).expect("memory reads");
        assert_eq!(input.window().len(), data.len());
        assert_eq!(input.buf.capacity(), data.len());
    }

    /// Every truncation of every input, plain and gzipped, each with one of the chunk
    /// sizes in turn.
    #[test]
    fn every_truncation_gives_what_memory_gives() {
        for (name, data, format) in cases().into_iter().take(4 * bases().len()) {
            let step = if data.len() > 10_000 { 97 } else { 1 };
            for cut in (0..data.len()).step_by(step) {
                let chunk = CHUNKS[cut % CHUNKS.len()];
                check(
                    &data[..cut],
                    format,
                    chunk,
                    cut % 2 == 0,
                    &format!("{name} cut at {cut}"),
                );
            }
        }
    }

    /// The seed corpus and the regressions of the fuzz targets of the streamed readers.
    #[test]
    fn fuzz_inputs_give_what_memory_gives() {
        let fuzz = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz");
        let mut seen = 0;
        for (target, format) in [
            ("read_ply", Format::Ply),
            ("read_stl", Format::Stl),
            ("read_off", Format::Off),
            ("read_obj", Format::Obj),
        ] {
            for kind in ["corpus", "regressions"] {
                let Ok(entries) = std::fs::read_dir(fuzz.join(kind).join(target)) else {
                    continue;
                };
                for path in entries.filter_map(|e| Some(e.ok()?.path())) {
                    let data = std::fs::read(&path).expect("a readable corpus file");
                    for (k, &chunk) in CHUNKS.iter().enumerate() {
                        check(
                            &data,
                            format,
                            chunk,
                            k % 2 == 1,
                            &path.display().to_string(),
                        );
                    }
                    seen += 1;
                }
            }
        }
        assert!(seen > 0, "no fuzz inputs under {}", fuzz.display());
    }

    /// A reader that fails after `left` bytes, as a file can.
    struct Failing<'a> {
        data: &'a [u8],
        left: usize,
    }

    impl Read for Failing<'_> {
        fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
            if self.left == 0 {
                return Err(std::io::Error::other("the disk went away"));
            }
            let n = out.len().min(self.left).min(self.data.len());
            out[..n].copy_from_slice(&self.data[..n]);
            (self.data, self.left) = (&self.data[n..], self.left - n);
            Ok(n)
        }
    }

    #[test]
    fn an_error_of_the_file_is_kept_apart_from_the_content() {
        let ply = written_ply();
        for data in [ply.clone(), gzip(&ply)] {
            let failing = Failing {
                data: &data,
                left: data.len() / 2,
            };
            let mut input =
                Input::reader(Box::new(failing), data.len() as u64, 64).expect("the start reads");
            assert!(read_input(&mut input, Format::Ply, None).is_err());
            let error = input.take_file_error().expect("the file's error");
            assert_eq!(error.to_string(), "the disk went away");
        }
    }
}
