//! XYZ and extended XYZ (`Lattice="..."`, `Properties=species:S:1:pos:R:3:...`, `pbc="T T T"`).

use super::lex::{fields, parse_f32, parse_usize, split_spans, trim, SymbolCache};
use super::{FrameParser, LineReader, ReadError};
use crate::{Cell, Molecule};

#[derive(Default)]
pub(crate) struct XyzParser {
    syms: SymbolCache,
}

/// Column layout of an atom line.
struct Layout {
    species: usize,
    pos: usize,
    ncols: usize,
    /// (name, first column, kind) of extra numeric columns; kind 'R', 'I' or 'L'.
    extra: Vec<(String, usize, u8)>,
}

impl Default for Layout {
    fn default() -> Self {
        Layout {
            species: 0,
            pos: 1,
            ncols: 4,
            extra: Vec::new(),
        }
    }
}

/// Split an extended-XYZ comment into key=value pairs (values may be quoted).
fn key_values(line: &[u8]) -> Vec<(String, String)> {
    let s = String::from_utf8_lossy(line);
    let mut out = Vec::new();
    let mut it = s.chars().peekable();
    loop {
        while it.peek().is_some_and(|c| c.is_whitespace()) {
            it.next();
        }
        if it.peek().is_none() {
            break;
        }
        let mut key = String::new();
        while let Some(&c) = it.peek() {
            if c == '=' || c.is_whitespace() {
                break;
            }
            key.push(c);
            it.next();
        }
        let mut val = String::new();
        if it.peek() == Some(&'=') {
            it.next();
            match it.peek() {
                Some(&q) if q == '"' || q == '\'' => {
                    it.next();
                    for c in it.by_ref() {
                        if c == q {
                            break;
                        }
                        val.push(c);
                    }
                }
                _ => {
                    while let Some(&c) = it.peek() {
                        if c.is_whitespace() {
                            break;
                        }
                        val.push(c);
                        it.next();
                    }
                }
            }
        }
        out.push((key, val));
    }
    out
}

fn parse_header(
    r: &LineReader,
    line_no: u64,
    line: &[u8],
) -> Result<(Layout, Option<Cell>), ReadError> {
    let mut layout = Layout::default();
    let mut cell = None;
    if !line.windows(1).any(|w| w[0] == b'=') {
        return Ok((layout, cell));
    }
    let kv = key_values(line);
    let mut pbc = [true; 3];
    for (k, v) in &kv {
        if k.eq_ignore_ascii_case("pbc") {
            for (i, t) in v.split_whitespace().take(3).enumerate() {
                pbc[i] = matches!(t, "T" | "t" | "True" | "true" | "1");
            }
        }
    }
    for (k, v) in &kv {
        if k.eq_ignore_ascii_case("Lattice") {
            let nums: Vec<f32> = v
                .split_whitespace()
                .filter_map(|t| parse_f32(t.as_bytes()))
                .collect();
            if nums.len() != 9 || nums.iter().any(|x| !x.is_finite()) {
                return Err(r.error(
                    line_no,
                    "Lattice=\"ax ay az bx by bz cx cy cz\" (9 finite numbers)",
                    v.as_bytes(),
                ));
            }
            cell = Some(Cell {
                origin: [0.0; 3],
                edges: [
                    [nums[0], nums[1], nums[2]],
                    [nums[3], nums[4], nums[5]],
                    [nums[6], nums[7], nums[8]],
                ],
                pbc,
            });
        } else if k.eq_ignore_ascii_case("Properties") {
            let parts: Vec<&str> = v.split(':').collect();
            if !parts.len().is_multiple_of(3) {
                return Err(r.error(line_no, "Properties=name:type:count triples", v.as_bytes()));
            }
            let mut col = 0usize;
            let mut species = None;
            let mut pos = None;
            let mut extra = Vec::new();
            for t in parts.chunks(3) {
                let n = parse_usize(t[2].as_bytes())
                    .filter(|&n| n > 0 && n < 1000)
                    .ok_or_else(|| {
                        r.error(line_no, "a column count in Properties", t[2].as_bytes())
                    })?;
                let kind = t[1]
                    .as_bytes()
                    .first()
                    .copied()
                    .unwrap_or(b'?')
                    .to_ascii_uppercase();
                match (t[0], kind) {
                    ("species", b'S') if species.is_none() => species = Some(col),
                    ("pos", b'R') if n == 3 && pos.is_none() => pos = Some(col),
                    (name, b'R' | b'I' | b'L') => {
                        for c in 0..n {
                            let nm = if n == 1 {
                                name.to_string()
                            } else {
                                format!("{name}_{c}")
                            };
                            extra.push((nm, col + c, kind));
                        }
                    }
                    _ => {}
                }
                col += n;
            }
            layout = Layout {
                species: species
                    .ok_or_else(|| r.error(line_no, "a species:S:1 property", v.as_bytes()))?,
                pos: pos.ok_or_else(|| r.error(line_no, "a pos:R:3 property", v.as_bytes()))?,
                ncols: col,
                extra,
            };
        }
    }
    Ok((layout, cell))
}

impl FrameParser for XyzParser {
    fn next_frame(&mut self, r: &mut LineReader) -> Result<Option<Molecule>, ReadError> {
        // Count line (blank lines between frames are tolerated).
        let n = loop {
            let Some((ln, line)) = r.next_line()? else {
                return Ok(None);
            };
            let t = trim(line);
            if t.is_empty() {
                continue;
            }
            let first = fields(t).next().unwrap_or(t);
            match parse_usize(first) {
                Some(n) if n <= (u32::MAX as usize) => break n,
                _ => {
                    let t = t.to_vec();
                    return Err(r.error(ln, "the number of atoms (XYZ count line)", &t));
                }
            }
        };
        let (ln, comment) = r.expect_line("the XYZ comment line")?;
        let comment = comment.to_vec();
        let (layout, cell) = parse_header(r, ln, &comment)?;
        let mut m = Molecule::with_capacity(n.min(1 << 26));
        m.cell = cell;
        let mut extra: Vec<Vec<f32>> = layout
            .extra
            .iter()
            .map(|_| Vec::with_capacity(n.min(1 << 26)))
            .collect();
        let path = r.path.clone();
        let simple = layout.species == 0 && layout.pos == 1 && layout.extra.is_empty();
        let mut spans: Vec<(usize, usize)> = Vec::with_capacity(layout.ncols);
        for _ in 0..n {
            let (ln, line) = match r.next_line()? {
                Some(l) => l,
                None => {
                    let next = r.line_no() + 1;
                    return Err(r.error(
                        next,
                        &format!("{n} atom lines (count line says {n}, got {})", m.len()),
                        b"end of file (truncated frame)",
                    ));
                }
            };
            let (sym, xyz) = if simple {
                let mut f = fields(line);
                let s = f.next();
                let (a, b, c) = (f.next(), f.next(), f.next());
                match (s, a, b, c) {
                    (Some(s), Some(a), Some(b), Some(c)) => (s, [a, b, c]),
                    _ => {
                        let l = line.to_vec();
                        return Err(r.error(ln, "an atom line 'symbol x y z'", &l));
                    }
                }
            } else {
                split_spans(line, &mut spans);
                if spans.len() < layout.ncols {
                    let l = line.to_vec();
                    return Err(r.error(
                        ln,
                        &format!("{} columns as declared by Properties", layout.ncols),
                        &l,
                    ));
                }
                let c = |k: usize| &line[spans[k].0..spans[k].1];
                (
                    c(layout.species),
                    [c(layout.pos), c(layout.pos + 1), c(layout.pos + 2)],
                )
            };
            let mut p = [0f32; 3];
            for k in 0..3 {
                match parse_f32(xyz[k]) {
                    Some(v) if v.is_finite() => p[k] = v,
                    Some(_) => {
                        let t = xyz[k].to_vec();
                        return Err(r.error(
                            ln,
                            "a finite coordinate (NaN/inf are not allowed)",
                            &t,
                        ));
                    }
                    None => {
                        let t = xyz[k].to_vec();
                        return Err(r.error(ln, "a number (coordinate)", &t));
                    }
                }
            }
            let z = self.syms.lookup(sym, &path, ln);
            if !simple {
                for (e, (_, col, kind)) in extra.iter_mut().zip(&layout.extra) {
                    let t = &line[spans[*col].0..spans[*col].1];
                    let v = if *kind == b'L' {
                        Some(if matches!(t, b"T" | b"True" | b"true") {
                            1.0
                        } else {
                            0.0
                        })
                    } else {
                        parse_f32(t)
                    };
                    match v {
                        Some(v) => e.push(v),
                        None => {
                            let t = t.to_vec();
                            return Err(r.error(ln, "a number", &t));
                        }
                    }
                }
            }
            m.push(p, z);
        }
        m.scalars = layout
            .extra
            .into_iter()
            .map(|(n, _, _)| n)
            .zip(extra)
            .collect();
        Ok(Some(m))
    }

    fn skip_frame(&mut self, r: &mut LineReader) -> Result<bool, ReadError> {
        let n = loop {
            let Some((ln, line)) = r.next_line()? else {
                return Ok(false);
            };
            let t = trim(line);
            if t.is_empty() {
                continue;
            }
            match parse_usize(fields(t).next().unwrap_or(t)) {
                Some(n) => break n,
                None => {
                    let t = t.to_vec();
                    return Err(r.error(ln, "the number of atoms (XYZ count line)", &t));
                }
            }
        };
        for i in 0..=n {
            if r.next_line()?.is_none() {
                let next = r.line_no() + 1;
                let what = if i == 0 {
                    "the XYZ comment line".to_string()
                } else {
                    format!("{n} atom lines")
                };
                return Err(r.error(next, &what, b"end of file (truncated frame)"));
            }
        }
        Ok(true)
    }

    fn warnings(&self) -> &[String] {
        &self.syms.warnings
    }
}
