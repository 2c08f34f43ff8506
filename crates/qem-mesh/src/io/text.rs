//! Byte-level helpers for the text formats: lines, tokens, numbers; and [`TextStream`],
//! which reads lines and tokens out of an [`Input`] a chunk at a time.

use super::input::Input;
use super::ReadError;

/// Lines of `data` with their 1-based numbers; `\r\n` and `\n` both end a line.
pub(crate) fn lines(data: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    let mut rest = Some(data);
    let mut no = 0usize;
    std::iter::from_fn(move || {
        let d = rest?;
        no += 1;
        let (line, next) = match d.iter().position(|&b| b == b'\n') {
            Some(i) => (&d[..i], d.get(i + 1..)),
            None => (d, None),
        };
        // A final newline does not start another (empty) line.
        rest = next.filter(|r| !r.is_empty());
        Some((no, line.strip_suffix(b"\r").unwrap_or(line)))
    })
}

/// How many lines of `data` are not valid UTF-8.
pub(crate) fn non_utf8_lines(data: &[u8]) -> usize {
    let mut count = Utf8Lines::default();
    count.pass(data);
    count.total()
}

/// Counts the lines that are not valid UTF-8 in text given in pieces, cut anywhere
/// (in a line, in a character): what is kept between pieces is whether the line being
/// passed is already known bad, and the bytes of a character cut at a piece's end.
#[derive(Default)]
struct Utf8Lines {
    /// Lines passed whole (up to their line break) that are not UTF-8.
    bad_lines: usize,
    /// The line being passed holds bytes that are not UTF-8.
    bad: bool,
    /// The start of a character cut at the last piece's end (at most 3 bytes).
    pending: [u8; 3],
    pending_len: usize,
}

impl Utf8Lines {
    /// Passes the next bytes of the text. Each byte is looked at a bounded number of
    /// times: valid text is checked in one run up to its first error (nearly every
    /// file is UTF-8, and one check of a run is much cheaper than one per line), a bad
    /// line is only searched for its end.
    fn pass(&mut self, mut bytes: &[u8]) {
        while !bytes.is_empty() {
            if self.bad {
                let Some(i) = bytes.iter().position(|&b| b == b'\n') else {
                    return;
                };
                self.bad_lines += 1;
                self.bad = false;
                bytes = &bytes[i + 1..];
            } else if self.pending_len > 0 {
                // Completes the cut character with the bytes it still needs (a
                // character is at most 4 bytes).
                let p = self.pending_len;
                let k = bytes.len().min(4 - p);
                let mut joined = [0u8; 4];
                joined[..p].copy_from_slice(&self.pending[..p]);
                joined[p..p + k].copy_from_slice(&bytes[..k]);
                match std::str::from_utf8(&joined[..p + k]) {
                    Ok(_) => {
                        self.pending_len = 0;
                        bytes = &bytes[k..];
                    }
                    // The first character is whole (and longer than the cut part).
                    Err(e) if e.valid_up_to() > 0 => {
                        self.pending_len = 0;
                        bytes = &bytes[e.valid_up_to() - p..];
                    }
                    // Not UTF-8: `bytes` may end the line, so they are searched.
                    Err(e) if e.error_len().is_some() => {
                        self.pending_len = 0;
                        self.bad = true;
                    }
                    // Still cut: all of `bytes` (fewer than it needs) is kept.
                    Err(_) => {
                        self.pending[..p + k].copy_from_slice(&joined[..p + k]);
                        self.pending_len = p + k;
                        return;
                    }
                }
            } else {
                match std::str::from_utf8(bytes) {
                    Ok(_) => return,
                    Err(e) => {
                        let valid = e.valid_up_to();
                        if e.error_len().is_some() {
                            self.bad = true;
                            bytes = &bytes[valid..];
                        } else {
                            // A character cut at the end (a line break would have made
                            // it an error): at most 3 bytes.
                            let cut = &bytes[valid..];
                            self.pending[..cut.len()].copy_from_slice(cut);
                            self.pending_len = cut.len();
                            return;
                        }
                    }
                }
            }
        }
    }

    /// The lines that are not UTF-8, the last one included when the text ends without
    /// a line break.
    fn total(&self) -> usize {
        self.bad_lines + usize::from(self.bad || self.pending_len > 0)
    }
}

/// `s` without leading ASCII whitespace.
pub(crate) fn trim_start(s: &[u8]) -> &[u8] {
    let i = s
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(s.len());
    &s[i..]
}

/// `s` without leading and trailing ASCII whitespace.
pub(crate) fn trim(s: &[u8]) -> &[u8] {
    &s[trimmed(s)]
}

/// Where `s` lies without leading and trailing ASCII whitespace (empty when it is all
/// whitespace).
pub(crate) fn trimmed(s: &[u8]) -> std::ops::Range<usize> {
    let i = s.len() - trim_start(s).len();
    let j = s
        .iter()
        .rposition(|b| !b.is_ascii_whitespace())
        .map_or(i, |j| j + 1);
    i..j
}

/// `line` cut at the first `comment` byte.
pub(crate) fn strip_comment(line: &[u8], comment: u8) -> &[u8] {
    match line.iter().position(|&b| b == comment) {
        Some(i) => &line[..i],
        None => line,
    }
}

/// The first line that is not blank once its comment is removed (trimmed).
pub(crate) fn first_content_line(data: &[u8], comment: u8) -> &[u8] {
    lines(data)
        .map(|(_, l)| trim(strip_comment(l, comment)))
        .find(|l| !l.is_empty())
        .unwrap_or(&[])
}

/// Whitespace-separated words of one line.
pub(crate) fn words(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|b| b.is_ascii_whitespace())
        .filter(|w| !w.is_empty())
}

/// Lines or tokens read out of an [`Input`] as it arrives, so that a text file is
/// parsed without holding it whole: what was read is consumed at each refill, and the
/// window holds about the line (or token) being read and a read, whatever the file's
/// size ([`Input`] grows its buffer only while one is longer than it).
///
/// Lines and line numbers are those of [`lines`] over the same bytes: `\r\n` and `\n`
/// end a line (a `\r\n` split between two reads included), a final line without a
/// line break is a line, a final line break does not start one. Tokens are separated
/// by ASCII whitespace, line breaks included.
pub(crate) struct TextStream<'i, 'a> {
    input: &'i mut Input<'a>,
    /// Bytes at the window's start already returned; consumed when the window is
    /// refilled (consuming per line would cost a call per line for nothing).
    pos: usize,
    /// Line number of the byte at `pos`.
    line: usize,
    /// The lines that are not UTF-8 among those consumed, when counted (see
    /// [`TextStream::count_non_utf8`]).
    non_utf8: Option<Utf8Lines>,
}

impl<'i, 'a> TextStream<'i, 'a> {
    /// Starts at the window's first byte, which is on line `first_line`.
    pub(crate) fn new(input: &'i mut Input<'a>, first_line: usize) -> Self {
        Self {
            input,
            pos: 0,
            line: first_line,
            non_utf8: None,
        }
    }

    /// Counts the lines that are not UTF-8 from here on, as [`non_utf8_lines`] counts
    /// them in the whole text; [`TextStream::non_utf8_lines`] gives the count once all
    /// the lines are read.
    pub(crate) fn count_non_utf8(&mut self) {
        self.non_utf8 = Some(Utf8Lines::default());
    }

    /// The lines that are not UTF-8 among those read since
    /// [`TextStream::count_non_utf8`] (0 when not counted), once all are read: the
    /// last line counts even without a line break.
    pub(crate) fn non_utf8_lines(&mut self) -> usize {
        self.release();
        self.non_utf8.as_ref().map_or(0, Utf8Lines::total)
    }

    /// Consumes what was returned (counting its lines that are not UTF-8, when
    /// counted).
    fn release(&mut self) {
        if let Some(count) = &mut self.non_utf8 {
            count.pass(self.input.window().get(..self.pos).unwrap_or_default());
        }
        self.input.consume(self.pos);
        self.pos = 0;
    }

    /// Consumes what was returned and reads more: the window then holds more bytes
    /// after the cursor than before, or all that is left.
    fn refill(&mut self) -> Result<(), ReadError> {
        self.release();
        let have = self.input.window().len();
        self.input.fill(have.saturating_add(1))
    }

    /// The next line (without its line break and one `\r` before it) as a range of
    /// [`TextStream::span`], and its number, or `None` at the end of the data.
    #[inline]
    pub(crate) fn next_line_span(
        &mut self,
    ) -> Result<Option<(usize, std::ops::Range<usize>)>, ReadError> {
        // Bytes after the cursor already searched: a line longer than a read is
        // searched once, not again from its start after each read.
        let mut searched = 0;
        let (start, mut end) = loop {
            let window = self.input.window();
            let rest = window.get(self.pos + searched..).unwrap_or_default();
            if let Some(i) = rest.iter().position(|&b| b == b'\n') {
                let start = self.pos;
                let end = start + searched + i;
                self.pos = end + 1;
                break (start, end);
            }
            if self.input.at_end() {
                if self.pos == window.len() {
                    return Ok(None);
                }
                let start = self.pos;
                self.pos = window.len();
                break (start, window.len());
            }
            searched = window.len() - self.pos;
            self.refill()?;
        };
        if end > start && self.input.window().get(end - 1) == Some(&b'\r') {
            end -= 1;
        }
        let no = self.line;
        self.line += 1;
        Ok(Some((no, start..end)))
    }

    /// The bytes of a span given by the last call to [`TextStream::next_line_span`].
    #[inline]
    pub(crate) fn span(&self, span: std::ops::Range<usize>) -> &[u8] {
        self.input.window().get(span).unwrap_or_default()
    }

    /// Line number of the cursor: of the last token returned, or of the next line.
    pub(crate) fn line(&self) -> usize {
        self.line
    }

    /// The next whitespace-separated token and its line, or `None` at the end of the
    /// data (the lines passed are counted: see [`TextStream::line`]).
    #[inline]
    pub(crate) fn next_token(&mut self) -> Result<Option<(&[u8], usize)>, ReadError> {
        // Bytes of the token already searched (after the cursor, which is at its
        // start): a token longer than a read is searched once.
        let mut searched = 0;
        let (start, end) = loop {
            let window = self.input.window();
            if searched == 0 {
                while let Some(&b) = window.get(self.pos) {
                    if !b.is_ascii_whitespace() {
                        break;
                    }
                    self.line += usize::from(b == b'\n');
                    self.pos += 1;
                }
            }
            let start = self.pos;
            let mut i = start + searched;
            while let Some(&b) = window.get(i) {
                if b.is_ascii_whitespace() {
                    break;
                }
                i += 1;
            }
            // A token that reaches the window's end may go on in the next read.
            if i < window.len() || self.input.at_end() {
                self.pos = i;
                break (start, i);
            }
            searched = i - start;
            self.refill()?;
        };
        Ok((end > start).then(|| (self.span(start..end), self.line)))
    }

    /// Skips to the end of the line (its line break is the next byte read); what is
    /// skipped is consumed as it is read.
    pub(crate) fn skip_line(&mut self) -> Result<(), ReadError> {
        loop {
            let window = self.input.window();
            let rest = window.get(self.pos..).unwrap_or_default();
            if let Some(i) = rest.iter().position(|&b| b == b'\n') {
                self.pos += i;
                return Ok(());
            }
            self.pos = window.len();
            if self.input.at_end() {
                return Ok(());
            }
            self.refill()?;
        }
    }

    /// Offset in the data of the cursor.
    pub(crate) fn offset(&self) -> u64 {
        self.input.offset() + self.pos as u64
    }

    /// Reads (and consumes) the rest of the data to count its bytes from the cursor:
    /// for an error that depends on the size of the rest. Lines not counted yet are
    /// left uncounted ([`TextStream::non_utf8_lines`] comes first).
    pub(crate) fn count_rest(&mut self) -> Result<u64, ReadError> {
        self.release();
        self.input.skip(u64::MAX)
    }

    /// The most bytes the rest of the data can hold ([`Input::could_hold`]).
    pub(crate) fn could_hold(&self) -> usize {
        self.input.could_hold()
    }
}

/// Parses a decimal floating-point number (Rust's syntax, which includes `inf` and
/// `nan`; callers check finiteness).
pub(crate) fn parse_f64(tok: &[u8]) -> Option<f64> {
    std::str::from_utf8(tok).ok()?.parse().ok()
}

/// Parses a decimal number straight to the nearest `f32` (attribute values: rounding
/// through `f64` first could, rarely, land on the other side of a halfway point).
pub(crate) fn parse_f32(tok: &[u8]) -> Option<f32> {
    std::str::from_utf8(tok).ok()?.parse().ok()
}

/// Parses a decimal integer with an optional sign (no allocation, overflow checked).
pub(crate) fn parse_i64(tok: &[u8]) -> Option<i64> {
    let (neg, digits) = match tok.split_first()? {
        (b'-', rest) => (true, rest),
        (b'+', rest) => (false, rest),
        _ => (false, tok),
    };
    if digits.is_empty() {
        return None;
    }
    let mut v: i64 = 0;
    for &d in digits {
        if !d.is_ascii_digit() {
            return None;
        }
        let d = i64::from(d - b'0');
        // Accumulate negatively so that i64::MIN parses too.
        v = v.checked_mul(10)?.checked_sub(d)?;
    }
    if neg {
        Some(v)
    } else {
        v.checked_neg()
    }
}

/// A token as shown in an error message: lossy UTF-8, at most 40 characters.
pub(crate) fn show(tok: &[u8]) -> String {
    let s = String::from_utf8_lossy(tok);
    if s.chars().count() > 40 {
        let cut: String = s.chars().take(40).collect();
        format!("\"{cut}...\"")
    } else {
        format!("\"{s}\"")
    }
}

/// Caps a claimed element count by what `remaining` bytes of text could hold, for
/// `Vec::with_capacity`: every element needs at least `min_bytes` bytes.
pub(crate) fn capacity_for(claimed: usize, remaining: usize, min_bytes: usize) -> usize {
    claimed.min(remaining / min_bytes.max(1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_number_and_strip_cr() {
        let v: Vec<_> = lines(b"a\r\nb\n\nc").collect();
        assert_eq!(v, vec![(1, &b"a"[..]), (2, b"b"), (3, b""), (4, b"c")]);
        assert_eq!(lines(b"a\n").count(), 1);
    }

    /// Every split of lines between reads (a `\r\n` cut in two, a line longer than a
    /// read, no final line break) gives the lines of [`lines`], and the count of lines
    /// that are not UTF-8 of [`non_utf8_lines`].
    #[test]
    fn streamed_lines_are_the_lines_of_the_whole() {
        let long = "x".repeat(5000);
        let texts: [&[u8]; 6] = [
            b"a\r\nb\n\nc",
            b"a\r\n\r\n\xe9\r\nlast\r\n",
            b"\n\n",
            b"one line, no break",
            b"\r\r\n\r",
            long.as_bytes(),
        ];
        for text in texts {
            let text = [text, b"\n", text].concat();
            for chunk in [1, 2, 3, 7, 4096] {
                let mut input =
                    Input::reader(Box::new(&text[..]), u64::MAX, chunk).expect("memory reads");
                let mut stream = TextStream::new(&mut input, 1);
                stream.count_non_utf8();
                let mut got = Vec::new();
                while let Some((no, span)) = stream.next_line_span().expect("memory reads") {
                    got.push((no, stream.span(span).to_vec()));
                }
                let want: Vec<_> = lines(&text).map(|(no, l)| (no, l.to_vec())).collect();
                assert_eq!(got, want, "{text:?} in chunks of {chunk}");
                assert_eq!(stream.non_utf8_lines(), non_utf8_lines(&text));
            }
        }
    }

    /// Lines that are not UTF-8 counted in pieces cut anywhere (in a character, at a
    /// line break) as a check of each whole line counts them.
    #[test]
    fn non_utf8_lines_counted_in_pieces() {
        let texts: [&[u8]; 8] = [
            "caf\u{e9}\nna\u{ef}ve \u{1F600}\n\u{20AC}".as_bytes(),
            b"caf\xe9\nok\n\xe9",
            b"\xe2\x82\n\xe2\x82\xac\n\xf0\x9f\x98",
            b"\xff\xfe junk\r\n\r\nfine\n",
            b"\xc3",
            b"\xe2\x82\xac\xe2",
            b"a\n\n\xc3\xa9\xc3\n",
            b"\xed\xa0\x80\n\xf4\x90\x80\x80\n",
        ];
        for text in texts {
            let want = lines(text)
                .filter(|(_, l)| std::str::from_utf8(l).is_err())
                .count();
            assert_eq!(non_utf8_lines(text), want, "{text:?}");
            for a in 0..=text.len() {
                for b in a..=text.len() {
                    let mut count = Utf8Lines::default();
                    for piece in [&text[..a], &text[a..b], &text[b..]] {
                        count.pass(piece);
                    }
                    assert_eq!(count.total(), want, "{text:?} cut at {a} and {b}");
                }
            }
        }
    }

    /// `count_rest` gives the bytes from the cursor to the end, whether lines are
    /// counted (which keeps the cursor's line in the window) or not, and after a byte
    /// order mark consumed as the STL reader consumes it (offsets then count it).
    #[test]
    fn count_rest_counts_from_the_cursor() {
        let text = b"solid a\nendsolid a";
        for bom in [false, true] {
            let data = if bom {
                [super::super::BOM, &text[..]].concat()
            } else {
                text.to_vec()
            };
            for count in [false, true] {
                for chunk in [1, 3, 4096] {
                    let mut input =
                        Input::reader(Box::new(&data[..]), u64::MAX, chunk).expect("memory reads");
                    input.fill(3).expect("memory reads");
                    input.consume(if bom { 3 } else { 0 });
                    let mut stream = TextStream::new(&mut input, 1);
                    if count {
                        stream.count_non_utf8();
                    }
                    stream.next_token().expect("memory reads");
                    let at = stream.offset();
                    assert_eq!(at, if bom { 8 } else { 5 });
                    let rest = stream.count_rest().expect("memory reads");
                    assert_eq!(at + rest, data.len() as u64, "bom {bom}, count {count}");
                }
            }
        }
    }

    /// A line (or token) much longer than a read comes out whole, read 64 bytes at a
    /// time. (Its cost is its length: the search for its end resumes where the last
    /// read left it. Before, each read searched the line again from its start: 2^14
    /// reads of this 1 MiB line looked at some 8 GiB, tens of seconds in a debug
    /// build. Not asserted here, a time bound being a flaky test; measured in d0d1c64.)
    #[test]
    fn a_long_line_read_in_small_pieces_comes_out_whole() {
        let long = "x".repeat(1 << 20);
        let crs = "\r".repeat(1 << 20);
        let cases = [
            format!("a\n{long}\nb\n"),
            format!("a\n{crs}\nb"),
            format!("a {long} b"),
        ];
        for text in &cases {
            for lines in [true, false] {
                let mut input =
                    Input::reader(Box::new(text.as_bytes()), u64::MAX, 64).expect("memory reads");
                let mut stream = TextStream::new(&mut input, 1);
                stream.count_non_utf8();
                let mut longest = 0;
                if lines {
                    while let Some((_, span)) = stream.next_line_span().expect("memory reads") {
                        longest = longest.max(span.len());
                    }
                } else {
                    while let Some((t, _)) = stream.next_token().expect("memory reads") {
                        longest = longest.max(t.len());
                    }
                }
                let short = !lines && !text.contains('x');
                assert!(longest >= (1 << 20) - 1 || short, "{longest}");
                assert_eq!(stream.non_utf8_lines(), 0);
            }
        }
    }

    #[test]
    fn parse_i64_edges() {
        assert_eq!(parse_i64(b"-9223372036854775808"), Some(i64::MIN));
        assert_eq!(parse_i64(b"9223372036854775808"), None);
        assert_eq!(parse_i64(b"+12"), Some(12));
        assert_eq!(parse_i64(b"-"), None);
        assert_eq!(parse_i64(b"1x"), None);
    }

    /// Tokens and their lines, whatever the reads cut: a token split between reads,
    /// a line break in a run of whitespace, a long token, no final line break;
    /// `skip_line` stops before the line break, which is then counted.
    #[test]
    fn streamed_tokens_count_lines() {
        let long = "y".repeat(300);
        let text = format!(" a\r\n\n\t bc  d\nsolid name \u{e9} x\n{long}\n\n e");
        for chunk in [1, 2, 3, 7, 4096] {
            let data = text.as_bytes();
            let mut input = Input::reader(Box::new(data), u64::MAX, chunk).expect("memory reads");
            let mut stream = TextStream::new(&mut input, 1);
            let mut got = Vec::new();
            while let Some((token, line)) = stream.next_token().expect("memory reads") {
                let token = String::from_utf8_lossy(token).into_owned();
                if token == "solid" {
                    stream.skip_line().expect("memory reads");
                }
                got.push((token, line));
            }
            let want = [
                ("a", 1),
                ("bc", 3),
                ("d", 3),
                ("solid", 4),
                (&long[..], 5),
                ("e", 7),
            ];
            let want: Vec<_> = want.iter().map(|&(t, l)| (t.to_string(), l)).collect();
            assert_eq!(got, want, "chunks of {chunk}");
            assert_eq!(stream.line(), 7);
        }
    }
}
