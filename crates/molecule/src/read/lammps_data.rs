//! LAMMPS data file (`read_data` input): header counts and box (with triclinic tilt), `Masses`,
//! `Atoms` (styles `atomic`, `charge`, `molecular`, `full`, with or without image flags) and
//! `Bonds`. Other sections are skipped. Atoms are sorted by id. Image flags, when present
//! (three extra integer columns), unwrap the positions: `x + ix·a + iy·b + iz·c` (as LAMMPS
//! `write_dump ... xu` and ASE do); when every atom line has them the frame is marked
//! [`Molecule::unwrapped`].
//!
//! Elements per type: [`super::ReadOptions::types`] first, else the nearest standard atomic
//! weight to the `Masses` entry (within 0.5 u) read as g/mol, else the same with the entry
//! read as kg/mol (×1000: `0.012` is C, for files written in SI units), else unknown (Z = 0,
//! with a warning).
//!
//! Consistency: the `Atoms` and (when the header declares bonds) `Bonds` sections must have
//! exactly the declared number of lines — a file cut short is an error naming the section the
//! file ended in — and every box `lo hi` pair must have `lo <= hi`.
//! Scalars: `id`, `type`, and `mol` / `q` when the style has them.

use super::lex::{fields, parse_f32, parse_f64, parse_i64, parse_usize, split_spans, trim, ErrCtx};
use super::{FrameParser, LineReader, ReadError, ReadOptions};
use crate::{elements, Cell, Molecule};
use std::collections::HashMap;

pub(crate) struct DataParser {
    opts: ReadOptions,
    done: bool,
    warnings: Vec<String>,
}

impl DataParser {
    pub(crate) fn new(opts: ReadOptions) -> DataParser {
        DataParser {
            opts,
            done: false,
            warnings: Vec::new(),
        }
    }
}

#[derive(PartialEq, Clone, Copy, Debug)]
enum Style {
    Atomic,
    Charge,
    Molecular,
    Full,
}

impl Style {
    fn from_name(s: &str) -> Option<Style> {
        Some(match s {
            "atomic" => Style::Atomic,
            "charge" => Style::Charge,
            "molecular" | "bond" | "angle" => Style::Molecular,
            "full" => Style::Full,
            _ => return None,
        })
    }
    /// (type column, x column, mol column, q column), 0-based.
    fn layout(self) -> (usize, usize, Option<usize>, Option<usize>) {
        match self {
            Style::Atomic => (1, 2, None, None),
            Style::Charge => (1, 3, None, Some(2)),
            Style::Molecular => (2, 3, Some(1), None),
            Style::Full => (2, 4, Some(1), Some(3)),
        }
    }
    fn ncols(self) -> usize {
        self.layout().1 + 3
    }
}

#[derive(PartialEq)]
enum Section {
    Header,
    Masses,
    Atoms,
    Bonds,
    Other,
}

fn strip_comment(l: &[u8]) -> (&[u8], &[u8]) {
    match memchr::memchr(b'#', l) {
        Some(i) => (trim(&l[..i]), trim(&l[i + 1..])),
        None => (trim(l), &[]),
    }
}

impl FrameParser for DataParser {
    fn next_frame(&mut self, r: &mut LineReader) -> Result<Option<Molecule>, ReadError> {
        if self.done {
            return Ok(None);
        }
        self.done = true;
        // Title line.
        if r.next_line()?.is_none() {
            return Ok(None);
        }
        let mut n_atoms: Option<usize> = None;
        let mut n_bonds: usize = 0;
        let mut lo_hi = [[0f64; 2]; 3];
        let mut have_box = [false; 3];
        let mut tilt = [0f64; 3];
        let mut masses: HashMap<i64, f64> = HashMap::new();
        let mut section = Section::Header;
        // Name and line of the section being read, for truncation errors.
        let mut section_name = String::from("header");
        let mut section_line = 1u64;
        let mut style: Option<Style> = None;
        // Atoms: (id, type, x, y, z, mol, q)
        // Atoms, structure-of-arrays in file order (sorted by id at the end).
        let mut ids: Vec<i64> = Vec::new();
        let mut types: Vec<i32> = Vec::new();
        let mut pos = Molecule::default();
        let mut mols: Vec<f32> = Vec::new();
        let mut qs: Vec<f32> = Vec::new();
        let mut bonds_raw: Vec<(u64, i64, i64)> = Vec::new();
        let mut spans = Vec::new();
        let mut has_mol = false;
        let mut has_q = false;
        // Every atom line had image flags (the positions are unwrapped by them).
        let mut all_images = true;
        let ec = r.ctx();
        while let Some((ln, line)) = r.next_line()? {
            let (body, comment) = strip_comment(line);
            if body.is_empty() {
                continue;
            }
            let first = body[0];
            if first.is_ascii_alphabetic() {
                // Section header.
                section_name = String::from_utf8_lossy(body).into_owned();
                section_line = ln;
                section = match body {
                    b"Masses" => Section::Masses,
                    b"Atoms" => {
                        let c = String::from_utf8_lossy(comment).trim().to_string();
                        if let Some(s) = Style::from_name(&c) {
                            style = Some(s);
                        } else if let Some(s) =
                            self.opts.atom_style.as_deref().and_then(Style::from_name)
                        {
                            style = Some(s);
                        }
                        Section::Atoms
                    }
                    b"Bonds" => Section::Bonds,
                    _ => Section::Other,
                };
                continue;
            }
            match section {
                Section::Header => {
                    let words: Vec<&[u8]> = fields(body).collect();
                    let num = |k: usize| words.get(k).and_then(|w| parse_f64(w));
                    let bad = |e: &ErrCtx, what: &str| e.error(ln, what, body);
                    if words.ends_with(&[&b"atoms"[..]]) && words.len() == 2 {
                        n_atoms = Some(
                            parse_usize(words[0]).ok_or_else(|| bad(&ec, "the number of atoms"))?,
                        );
                    } else if words.ends_with(&[&b"bonds"[..]]) && words.len() == 2 {
                        n_bonds =
                            parse_usize(words[0]).ok_or_else(|| bad(&ec, "the number of bonds"))?;
                    } else if let Some(k) = [&b"xlo"[..], b"ylo", b"zlo"]
                        .iter()
                        .position(|w| words.len() == 4 && words[2] == *w)
                    {
                        match (num(0), num(1)) {
                            (Some(a), Some(b)) if a.is_finite() && b.is_finite() && a > b => {
                                return Err(bad(&ec, "a box with lo <= hi"))
                            }
                            (Some(a), Some(b)) if a.is_finite() && b.is_finite() => {
                                lo_hi[k] = [a, b];
                                have_box[k] = true;
                            }
                            _ => return Err(bad(&ec, "'lo hi xlo xhi' with two finite numbers")),
                        }
                    } else if words.len() == 6 && words[3] == b"xy" {
                        match (num(0), num(1), num(2)) {
                            (Some(a), Some(b), Some(c))
                                if a.is_finite() && b.is_finite() && c.is_finite() =>
                            {
                                tilt = [a, b, c]
                            }
                            _ => {
                                return Err(bad(
                                    &ec,
                                    "'xy xz yz' tilt factors (three finite numbers)",
                                ))
                            }
                        }
                    }
                }
                Section::Masses => {
                    let mut w = fields(body);
                    match (w.next().and_then(parse_i64), w.next().and_then(parse_f64)) {
                        (Some(t), Some(m)) => {
                            masses.insert(t, m);
                        }
                        _ => return Err(ec.error(ln, "a Masses line 'type mass'", body)),
                    }
                }
                Section::Atoms => {
                    split_spans(body, &mut spans);
                    let st = match style {
                        Some(s) => s,
                        None => {
                            let s = match spans.len() {
                                5 | 8 => Style::Atomic,
                                6 | 9 => Style::Charge,
                                7 | 10 => Style::Full,
                                _ => return Err(ec.error(ln, "an Atoms line of style atomic/charge/molecular/full (add '# style' after 'Atoms')", body)),
                            };
                            style = Some(s);
                            s
                        }
                    };
                    if spans.len() < st.ncols() {
                        return Err(ec.error(
                            ln,
                            &format!("{} columns for atom style {st:?}", st.ncols()),
                            body,
                        ));
                    }
                    let f = |k: usize| &body[spans[k].0..spans[k].1];
                    let (tc, xc, mc, qc) = st.layout();
                    let id =
                        parse_i64(f(0)).ok_or_else(|| ec.error(ln, "an integer atom id", f(0)))?;
                    let ty = parse_i64(f(tc))
                        .and_then(|t| i32::try_from(t).ok())
                        .ok_or_else(|| ec.error(ln, "an integer atom type", f(tc)))?;
                    let mut p = [0f64; 3];
                    for (k, pk) in p.iter_mut().enumerate() {
                        match parse_f64(f(xc + k)) {
                            Some(v) if v.is_finite() => *pk = v,
                            Some(_) => {
                                return Err(ec.error(
                                    ln,
                                    "a finite coordinate (NaN/inf are not allowed)",
                                    f(xc + k),
                                ))
                            }
                            None => return Err(ec.error(ln, "a number (coordinate)", f(xc + k))),
                        }
                    }
                    let mut image = [0i64; 3];
                    all_images &= spans.len() >= st.ncols() + 3;
                    if spans.len() >= st.ncols() + 3 {
                        for (k, im) in image.iter_mut().enumerate() {
                            match parse_i64(f(st.ncols() + k)) {
                                Some(v) => *im = v,
                                None => {
                                    return Err(ec.error(
                                        ln,
                                        "an integer image flag",
                                        f(st.ncols() + k),
                                    ))
                                }
                            }
                        }
                    }
                    let mol = match mc {
                        Some(c) => {
                            has_mol = true;
                            parse_f32(f(c)).ok_or_else(|| ec.error(ln, "a molecule id", f(c)))?
                        }
                        None => 0.0,
                    };
                    let q = match qc {
                        Some(c) => {
                            has_q = true;
                            parse_f32(f(c)).ok_or_else(|| ec.error(ln, "a charge", f(c)))?
                        }
                        None => 0.0,
                    };
                    if ids.is_empty() {
                        let cap = n_atoms.unwrap_or(0).min(1 << 26);
                        ids.reserve(cap);
                        types.reserve(cap);
                        pos = Molecule::with_capacity(cap);
                    }
                    if image != [0; 3] {
                        let e = [
                            [lo_hi[0][1] - lo_hi[0][0], 0.0, 0.0],
                            [tilt[0], lo_hi[1][1] - lo_hi[1][0], 0.0],
                            [tilt[1], tilt[2], lo_hi[2][1] - lo_hi[2][0]],
                        ];
                        for (k, pk) in p.iter_mut().enumerate() {
                            *pk += image[0] as f64 * e[0][k]
                                + image[1] as f64 * e[1][k]
                                + image[2] as f64 * e[2][k];
                        }
                    }
                    // Unwrapped by the image flags and rounded to f32 first, then checked.
                    let pf = p.map(|v| v as f32);
                    if pf.iter().any(|v| !v.is_finite()) {
                        return Err(ec.error(
                            ln,
                            "a position that stays finite in f32 after unwrapping (image flags)",
                            body,
                        ));
                    }
                    ids.push(id);
                    types.push(ty);
                    pos.push(pf, 0);
                    if mc.is_some() {
                        mols.push(mol);
                    }
                    if qc.is_some() {
                        qs.push(q);
                    }
                }
                Section::Bonds => {
                    let w: Vec<&[u8]> = fields(body).take(4).collect();
                    let ok = w.len() == 4 && parse_i64(w[1]).is_some();
                    match (
                        ok,
                        w.get(2).and_then(|x| parse_i64(x)),
                        w.get(3).and_then(|x| parse_i64(x)),
                    ) {
                        (true, Some(a), Some(b)) => bonds_raw.push((ln, a, b)),
                        _ => return Err(ec.error(ln, "a Bonds line 'id type atom1 atom2'", body)),
                    }
                }
                Section::Other => {}
            }
        }
        let Some(n) = n_atoms else {
            let next = r.line_no() + 1;
            return Err(r.error(next, "an 'N atoms' header line", b"end of file"));
        };
        let ended = format!("the file ends in section {section_name} (line {section_line})");
        if ids.len() != n {
            let next = r.line_no() + 1;
            return Err(r.error(
                next,
                &format!("{n} lines in the Atoms section (header says {n} atoms)"),
                format!("{} atom lines; {ended}", ids.len()).as_bytes(),
            ));
        }
        if bonds_raw.len() != n_bonds {
            let next = r.line_no() + 1;
            return Err(r.error(
                next,
                &format!("{n_bonds} lines in the Bonds section (header says {n_bonds} bonds)"),
                format!("{} bond lines; {ended}", bonds_raw.len()).as_bytes(),
            ));
        }
        // Sort by id; ids are freed before the other columns are permuted.
        let mut perm: Vec<u32> = (0..n as u32).collect();
        perm.sort_unstable_by_key(|&i| ids[i as usize]);
        let sorted_ids: Vec<i64> = perm.iter().map(|&i| ids[i as usize]).collect();
        drop(ids);
        if sorted_ids.windows(2).any(|w| w[0] == w[1]) {
            let next = r.line_no();
            return Err(r.error(
                next,
                "unique atom ids in the Atoms section",
                b"a duplicate id",
            ));
        }
        let mut m = pos;
        m.unwrapped = all_images && !m.is_empty();
        let mut type_z: HashMap<i32, u8> = HashMap::new();
        for (e, &ty) in m.elements.iter_mut().zip(&types) {
            *e = match type_z.get(&ty) {
                Some(&z) => z,
                None => {
                    let z = u32::try_from(ty)
                        .ok()
                        .and_then(|t| self.opts.type_element(t))
                        .or_else(|| {
                            let m = *masses.get(&i64::from(ty))?;
                            // g/mol first; kg/mol (SI files) only when nothing matches.
                            elements::by_mass(m as f32)
                                .or_else(|| elements::by_mass((m * 1000.0) as f32))
                        });
                    let z = z.unwrap_or_else(|| {
                        self.warnings.push(format!(
                            "{}: atom type {ty} has no element (no matching mass, not in --types); treated as unknown (Z = 0)",
                            r.path.display()
                        ));
                        0
                    });
                    type_z.insert(ty, z);
                    z
                }
            };
        }
        m.scalars
            .push(("type".into(), types.iter().map(|&t| t as f32).collect()));
        drop(types);
        if has_mol {
            m.scalars.push(("mol".into(), mols));
        }
        if has_q {
            m.scalars.push(("q".into(), qs));
        }
        // Everything above is in file order: permute it all into id order.
        super::dump::apply_perm(&mut m, &perm);
        drop(perm);
        m.scalars.insert(
            0,
            ("id".into(), sorted_ids.iter().map(|&i| i as f32).collect()),
        );
        if have_box.iter().all(|&b| b) {
            let [x, y, z] = lo_hi;
            m.cell = Some(Cell {
                origin: [x[0] as f32, y[0] as f32, z[0] as f32],
                edges: [
                    [(x[1] - x[0]) as f32, 0.0, 0.0],
                    [tilt[0] as f32, (y[1] - y[0]) as f32, 0.0],
                    [tilt[1] as f32, tilt[2] as f32, (z[1] - z[0]) as f32],
                ],
                pbc: [true; 3],
            });
        }
        if !bonds_raw.is_empty() {
            let index = |id: i64| sorted_ids.binary_search(&id).ok();
            let mut bonds = Vec::with_capacity(bonds_raw.len());
            for &(ln, a, b) in &bonds_raw {
                match (index(a), index(b)) {
                    (Some(i), Some(j)) if i != j => bonds.push([i.min(j) as u32, i.max(j) as u32]),
                    _ => {
                        let t = format!("{a} {b}");
                        return Err(r.error(
                            ln,
                            "a bond between two different existing atom ids",
                            t.as_bytes(),
                        ));
                    }
                }
            }
            bonds.sort_unstable();
            bonds.dedup();
            m.file_bonds = Some(bonds);
        }
        Ok(Some(m))
    }

    fn warnings(&self) -> &[String] {
        &self.warnings
    }
}
