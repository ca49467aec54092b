//! Byte-level line reading and number parsing shared by the readers.

use super::ReadError;
use std::io::{self, Read};
use std::path::Path;
use std::sync::Arc;

const INITIAL_BUF: usize = 1 << 20;
/// Longest accepted line; longer means binary garbage or a broken file.
const MAX_LINE: usize = 64 << 20;

/// Buffered reader yielding lines as byte slices (no copy, `\r\n` tolerated), tracking the
/// 1-based line number and the decoded byte offset.
pub(crate) struct LineReader {
    src: Box<dyn Read + Send>,
    buf: Vec<u8>,
    pos: usize,
    end: usize,
    eof: bool,
    checked_binary: bool,
    line_no: u64,
    offset: u64,
    pub(crate) path: Arc<Path>,
    /// Frame being read (for error messages).
    pub(crate) frame: usize,
    /// Asked before each refill of the buffer: true stops the read with
    /// [`ReadError::Cancelled`].
    pub(crate) cancel: Option<CancelTest>,
}

/// A caller's test of whether the frame being read is still wanted (true: stop).
pub type CancelTest = Arc<dyn Fn() -> bool + Send + Sync>;

impl LineReader {
    pub(crate) fn new(src: Box<dyn Read + Send>, path: Arc<Path>) -> LineReader {
        LineReader {
            src,
            buf: vec![0; INITIAL_BUF],
            pos: 0,
            end: 0,
            eof: false,
            checked_binary: false,
            line_no: 0,
            offset: 0,
            path,
            frame: 0,
            cancel: None,
        }
    }

    /// Declare that the stream starts at decoded byte `offset`, after `lines` lines.
    pub(crate) fn set_position(&mut self, offset: u64, lines: u64) {
        self.offset = offset;
        self.line_no = lines;
        self.checked_binary = true;
    }

    /// Number of lines returned so far (= line number of the last line).
    pub(crate) fn line_no(&self) -> u64 {
        self.line_no
    }

    /// Decoded byte offset of the next line.
    pub(crate) fn offset(&self) -> u64 {
        self.offset
    }

    fn fill(&mut self) -> Result<(), ReadError> {
        if self.cancel.as_ref().is_some_and(|c| c()) {
            return Err(ReadError::Cancelled {
                path: self.path.to_path_buf(),
            });
        }
        if self.pos > 0 {
            self.buf.copy_within(self.pos..self.end, 0);
            self.end -= self.pos;
            self.pos = 0;
        }
        if self.end == self.buf.len() {
            if self.buf.len() >= MAX_LINE {
                return Err(self.error(
                    self.line_no + 1,
                    "a line shorter than 64 MiB (is this a text file?)",
                    b"a line without newline",
                ));
            }
            let n = self.buf.len() * 2;
            self.buf.resize(n, 0);
        }
        loop {
            match self.src.read(&mut self.buf[self.end..]) {
                Ok(0) => {
                    self.eof = true;
                    break;
                }
                Ok(n) => {
                    self.end += n;
                    break;
                }
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => {
                    return Err(ReadError::Io {
                        path: self.path.to_path_buf(),
                        error: e,
                    })
                }
            }
        }
        if !self.checked_binary && (self.end >= 4096 || self.eof) {
            self.checked_binary = true;
            let head = &self.buf[..self.end.min(4096)];
            if head.contains(&0) {
                return Err(self.error(1, "a text file", b"binary data (NUL bytes)"));
            }
        }
        Ok(())
    }

    /// Next line (without the line terminator) and its 1-based number; `None` at end of file.
    pub(crate) fn next_line(&mut self) -> Result<Option<(u64, &[u8])>, ReadError> {
        loop {
            if self.checked_binary || self.eof {
                if let Some(i) = memchr::memchr(b'\n', &self.buf[self.pos..self.end]) {
                    let start = self.pos;
                    let mut e = start + i;
                    self.pos = e + 1;
                    self.offset += (i + 1) as u64;
                    self.line_no += 1;
                    if e > start && self.buf[e - 1] == b'\r' {
                        e -= 1;
                    }
                    return Ok(Some((self.line_no, &self.buf[start..e])));
                }
                if self.eof {
                    if self.pos < self.end {
                        let start = self.pos;
                        let mut e = self.end;
                        self.offset += (e - start) as u64;
                        self.pos = self.end;
                        self.line_no += 1;
                        if self.buf[e - 1] == b'\r' {
                            e -= 1;
                        }
                        return Ok(Some((self.line_no, &self.buf[start..e])));
                    }
                    return Ok(None);
                }
            }
            self.fill()?;
        }
    }

    /// Next line, or a "truncated" error saying what was expected.
    pub(crate) fn expect_line(&mut self, expected: &str) -> Result<(u64, &[u8]), ReadError> {
        let next = self.line_no + 1;
        if self.next_line()?.is_none() {
            return Err(self.error(next, expected, b"end of file (truncated)"));
        }
        // Re-borrow the line just returned (it is still in the buffer).
        Ok((self.line_no, self.last_line()))
    }

    /// The line most recently returned by `next_line` (only valid right after it).
    fn last_line(&self) -> &[u8] {
        // pos points just past the last '\n' (or at end). Walk back to find the line start.
        let end = self.pos;
        let mut e = end;
        if e > 0 && self.buf[e - 1] == b'\n' {
            e -= 1;
        }
        let start = memchr::memrchr(b'\n', &self.buf[..e]).map_or(0, |i| i + 1);
        let mut e2 = e;
        if e2 > start && self.buf[e2 - 1] == b'\r' {
            e2 -= 1;
        }
        &self.buf[start..e2]
    }

    /// Error context (file and frame) detached from the reader's borrow.
    pub(crate) fn ctx(&self) -> ErrCtx {
        ErrCtx {
            path: self.path.clone(),
            frame: self.frame,
        }
    }

    /// Build a parse error at `line`.
    pub(crate) fn error(&self, line: u64, expected: &str, found: &[u8]) -> ReadError {
        ReadError::Parse {
            path: self.path.to_path_buf(),
            line,
            frame: self.frame,
            expected: expected.to_string(),
            found: show(found),
        }
    }
}

/// File and frame for building errors while a line is borrowed from the reader.
pub(crate) struct ErrCtx {
    path: Arc<Path>,
    frame: usize,
}

impl ErrCtx {
    /// Build a parse error at `line`.
    pub(crate) fn error(&self, line: u64, expected: &str, found: &[u8]) -> ReadError {
        ReadError::Parse {
            path: self.path.to_path_buf(),
            line,
            frame: self.frame,
            expected: expected.to_string(),
            found: show(found),
        }
    }
}

/// Abbreviated, printable rendering of some input bytes for error messages.
pub(crate) fn show(b: &[u8]) -> String {
    if b.is_empty() {
        return "an empty line".to_string();
    }
    let s = String::from_utf8_lossy(&b[..b.len().min(60)]);
    let s: String = s
        .chars()
        .map(|c| if c.is_control() { '?' } else { c })
        .collect();
    if b.len() > 60 {
        format!("'{s}…'")
    } else {
        format!("'{s}'")
    }
}

/// Strip ASCII whitespace on both sides.
pub(crate) fn trim(b: &[u8]) -> &[u8] {
    b.trim_ascii()
}

/// Iterator over whitespace-separated fields of a line.
pub(crate) struct Fields<'a> {
    b: &'a [u8],
    i: usize,
}

impl<'a> Iterator for Fields<'a> {
    type Item = &'a [u8];
    #[inline]
    fn next(&mut self) -> Option<&'a [u8]> {
        let b = self.b;
        let mut i = self.i;
        while i < b.len() && b[i].is_ascii_whitespace() {
            i += 1;
        }
        if i >= b.len() {
            self.i = i;
            return None;
        }
        let s = i;
        while i < b.len() && !b[i].is_ascii_whitespace() {
            i += 1;
        }
        self.i = i;
        Some(&b[s..i])
    }
}

/// Whitespace-separated fields.
#[inline]
pub(crate) fn fields(b: &[u8]) -> Fields<'_> {
    Fields { b, i: 0 }
}

/// Split `line` into whitespace-separated field spans `(start, end)`, appended to `out`.
#[inline]
pub(crate) fn split_spans(line: &[u8], out: &mut Vec<(usize, usize)>) {
    out.clear();
    let mut i = 0;
    let n = line.len();
    while i < n {
        while i < n && line[i].is_ascii_whitespace() {
            i += 1;
        }
        if i >= n {
            break;
        }
        let s = i;
        while i < n && !line[i].is_ascii_whitespace() {
            i += 1;
        }
        out.push((s, i));
    }
}

/// Parse a float (`f64`); accepts Fortran `D` exponents. `None` if not a number.
#[inline]
pub(crate) fn parse_f64(b: &[u8]) -> Option<f64> {
    match fast_float2::parse::<f64, _>(b) {
        Ok(v) => Some(v),
        Err(_) => {
            if b.iter().any(|&c| c == b'd' || c == b'D') {
                let v: Vec<u8> = b
                    .iter()
                    .map(|&c| if c == b'd' || c == b'D' { b'e' } else { c })
                    .collect();
                fast_float2::parse::<f64, _>(&v).ok()
            } else {
                None
            }
        }
    }
}

/// Parse an `f32`, with a fast path for short integers (ids, types).
#[inline]
pub(crate) fn parse_f32(b: &[u8]) -> Option<f32> {
    if !b.is_empty() && b.len() <= 7 && b.iter().all(u8::is_ascii_digit) {
        let mut v = 0u32;
        for &c in b {
            v = v * 10 + u32::from(c - b'0');
        }
        return Some(v as f32);
    }
    match fast_float2::parse::<f32, _>(b) {
        Ok(v) => Some(v),
        Err(_) => parse_f64(b).map(|v| v as f32),
    }
}

/// Parse a non-negative integer (no sign, no spaces).
#[inline]
pub(crate) fn parse_usize(b: &[u8]) -> Option<usize> {
    if b.is_empty() || b.len() > 19 {
        return None;
    }
    let mut v: usize = 0;
    for &c in b {
        if !c.is_ascii_digit() {
            return None;
        }
        v = v.checked_mul(10)?.checked_add((c - b'0') as usize)?;
    }
    Some(v)
}

/// Parse a signed integer.
#[inline]
pub(crate) fn parse_i64(b: &[u8]) -> Option<i64> {
    match b.first() {
        Some(b'-') => parse_usize(&b[1..])
            .and_then(|v| i64::try_from(v).ok())
            .map(|v| -v),
        Some(b'+') => parse_usize(&b[1..]).and_then(|v| i64::try_from(v).ok()),
        _ => parse_usize(b).and_then(|v| i64::try_from(v).ok()),
    }
}

/// Cache for symbol → atomic number lookups (symbols repeat a lot).
#[derive(Default)]
pub(crate) struct SymbolCache {
    last: Vec<u8>,
    last_z: u8,
    pub(crate) warnings: Vec<String>,
    unknown: Vec<Vec<u8>>,
}

impl SymbolCache {
    /// Atomic number for a symbol (or a number 1..=103); unknown symbols give 0 and one
    /// warning per distinct symbol.
    #[inline]
    pub(crate) fn lookup(&mut self, sym: &[u8], path: &Path, line: u64) -> u8 {
        if sym == self.last.as_slice() && !sym.is_empty() {
            return self.last_z;
        }
        let z = match std::str::from_utf8(sym).ok().and_then(|s| {
            crate::elements::by_symbol(s).or_else(|| {
                s.parse::<u8>()
                    .ok()
                    .filter(|&n| (1..=crate::elements::MAX_Z).contains(&n))
            })
        }) {
            Some(z) => z,
            None => {
                if !self.unknown.iter().any(|u| u == sym) && self.unknown.len() < 100 {
                    self.unknown.push(sym.to_vec());
                    self.warnings.push(format!(
                        "{}:{line}: unknown element {}; treated as unknown (Z = 0)",
                        path.display(),
                        show(sym)
                    ));
                }
                0
            }
        };
        self.last.clear();
        self.last.extend_from_slice(sym);
        self.last_z = z;
        z
    }
}
